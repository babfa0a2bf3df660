#include "gi/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "gi/errors.h"

namespace gi {
namespace {

// Closes the descriptor on every path out.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Opens `path` for reading without blocking (a FIFO would otherwise wait for a writer) and
// checks it is a regular file within the size limit. On failure returns the kind and the
// problem; on success the open descriptor and the size.
bool openChecked(const std::string& path, const std::string& what, uint64_t maxBytes, Fd& file,
                 uint64_t& size, ErrorKind& kind, std::string& problem) {
  kind = ErrorKind::FileNotFound;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    problem = errno == ENOENT || errno == ENOTDIR
                  ? "file does not exist"
                  : std::string("cannot read: ") + std::strerror(errno);
    return false;
  }
  if (S_ISDIR(st.st_mode)) {
    problem = "is a directory, not a " + what;
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    problem = "is not a regular file (a device, FIFO or socket); only regular files are read";
    return false;
  }
  file.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (file.fd < 0 || ::fstat(file.fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    problem = std::string("cannot open the file for reading: ") + std::strerror(errno);
    return false;
  }
  size = uint64_t(st.st_size);
  if (size > maxBytes) {
    kind = ErrorKind::Unsupported;
    problem = "is " + std::to_string(size) + " bytes; input files larger than " +
              std::to_string(maxBytes) + " bytes are not read";
    return false;
  }
  return true;
}

template <class Bytes>
bool readAll(const std::string& path, const std::string& what, uint64_t maxBytes, Bytes& out,
             ErrorKind& kind, std::string& problem) {
  Fd file;
  uint64_t size = 0;
  if (!openChecked(path, what, maxBytes, file, size, kind, problem)) return false;
  out.resize(size_t(size));
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t n =
        ::read(file.fd, reinterpret_cast<char*>(out.data()) + done, out.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      problem = std::string("cannot read the file: ") + std::strerror(errno);
      return false;
    }
    if (n == 0) break;  // shrank while being read: keep what was there
    done += size_t(n);
  }
  out.resize(done);
  return true;
}

}  // namespace

uint64_t checkInputFile(const std::string& path, const std::string& what, uint64_t maxBytes) {
  Fd file;
  uint64_t size = 0;
  ErrorKind kind{};
  std::string problem;
  if (!openChecked(path, what, maxBytes, file, size, kind, problem))
    throw Error(kind, path, problem);
  return size;
}

std::string readInputFile(const std::string& path, const std::string& what, uint64_t maxBytes) {
  std::string text;
  ErrorKind kind{};
  std::string problem;
  if (!readAll(path, what, maxBytes, text, kind, problem)) throw Error(kind, path, problem);
  return text;
}

bool tryReadInputFile(const std::string& path, std::vector<unsigned char>& bytes,
                      std::string& problem, const std::string& what, uint64_t maxBytes) {
  ErrorKind kind{};
  return readAll(path, what, maxBytes, bytes, kind, problem);
}

nlohmann::json parseJsonText(std::string_view text, const std::string& path, bool allowComments) {
  try {
    return nlohmann::json::parse(text.begin(), text.end(), nullptr, true, allowComments);
  } catch (const nlohmann::json::out_of_range& e) {
    // 406: "number overflow parsing '1e400'"; say which number and why, not the exception.
    const std::string what = e.what();
    const size_t open = what.find('\''), close = what.rfind('\'');
    const std::string number =
        open != std::string::npos && close > open ? what.substr(open, close - open + 1) : "";
    throw Error(ErrorKind::InvalidData, path,
                "number " + (number.empty() ? std::string() : number + " ") +
                    "is out of range (beyond +-1.8e308, the largest double)");
  } catch (const nlohmann::json::exception& e) {
    // nlohmann's message carries "line L, column C".
    throw Error(ErrorKind::Parse, path, std::string("invalid JSON: ") + e.what());
  }
}

}  // namespace gi
