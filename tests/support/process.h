// Runs a command line and captures its exit code and combined output (tests of the CLIs).
#pragma once

#include <string>

namespace gi::test {

struct ProcessResult {
  int exitCode = -1;
  std::string output;  // stdout and stderr together
};

ProcessResult runCommand(const std::string& commandLine);
// A fresh empty temporary folder for one test.
std::string makeTempDir(const std::string& name);

}  // namespace gi::test
