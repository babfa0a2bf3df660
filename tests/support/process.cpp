#include "process.h"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>

namespace gi::test {

ProcessResult runCommand(const std::string& commandLine) {
  ProcessResult r;
  FILE* pipe = popen((commandLine + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.output.append(buffer.data(), n);
  int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string makeTempDir(const std::string& name) {
  // Per process, so test cases that ctest runs in parallel never share (or delete) a folder.
  auto dir =
      std::filesystem::temp_directory_path() / ("gi-test-" + std::to_string(getpid()) + "-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace gi::test
