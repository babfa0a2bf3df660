#include "cli.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "gi/image_io.h"

namespace gi::cli {

namespace fs = std::filesystem;

std::string formatNumber(double v) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  if (ec != std::errc()) return std::to_string(v);
  std::string s(buf, end);
  // 1e+09 -> 1e9, 1e-09 -> 1e-9: the exponent as one writes it.
  if (const size_t e = s.find('e'); e != std::string::npos) {
    size_t digits = e + 1;
    if (s[digits] == '+')
      s.erase(digits, 1);
    else if (s[digits] == '-')
      ++digits;
    while (digits + 1 < s.size() && s[digits] == '0') s.erase(digits, 1);
  }
  return s;
}

namespace {

std::string_view withoutPlus(std::string_view s) {
  if (s.size() > 1 && s.front() == '+' && s[1] != '-') s.remove_prefix(1);
  return s;
}

// 'text' (built with append: GCC 12 warns falsely (-Wrestrict) on "'" + string + "'").
std::string inQuotes(std::string_view text) {
  return std::string("'").append(text).append("'");
}

// "[lo, hi]" or "(lo, hi]".
std::string rangeText(char open, const std::string& lo, const std::string& hi) {
  return std::string(1, open).append(lo).append(", ").append(hi).append("]");
}

bool set(std::string* problem, const std::string& why) {
  if (problem) *problem = why;
  return false;
}

bool isHex(std::string_view s) {
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
  return s.size() > 1 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
}

}  // namespace

std::optional<double> parseDouble(std::string_view text, std::string* problem) {
  const std::string_view s = withoutPlus(text);
  if (isHex(s)) {
    set(problem, "is hexadecimal (only decimal numbers are read)");
    return std::nullopt;
  }
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v,
                                         std::chars_format::general);  // no hex
  if (s.empty() || end != s.data() + s.size() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    set(problem, "is not a number");
    return std::nullopt;
  }
  if (ec == std::errc::result_out_of_range) {
    const bool tiny = s.find_first_of("eE") != std::string_view::npos &&
                      s.find("-", s.find_first_of("eE")) != std::string_view::npos;
    if (!tiny) {
      set(problem, "is out of range (beyond +-1.8e308, the largest double)");
      return std::nullopt;
    }
    v = 0.0;  // below the smallest double: zero, then range-checked as such
  }
  if (!std::isfinite(v)) {  // from_chars reads "inf" and "nan"
    set(problem, "is not a finite number");
    return std::nullopt;
  }
  return v;
}

std::optional<int64_t> parseInteger(std::string_view text, std::string* problem) {
  const std::string_view s = withoutPlus(text);
  int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, 10);
  if (ec == std::errc::result_out_of_range) {
    set(problem, "is out of range for an integer");
    return std::nullopt;
  }
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) {
    std::string why;
    set(problem, parseDouble(text, &why) ? "is not an integer" : why);
    return std::nullopt;
  }
  return v;
}

std::vector<std::string> splitList(const std::string& flag, const std::string& text,
                                   bool allowDuplicates) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    std::string item = text.substr(start, comma == std::string::npos ? comma : comma - start);
    if (item.empty())
      throw Error(ErrorKind::Usage, flag, "empty item in the list " + inQuotes(text));
    if (!allowDuplicates)
      for (const std::string& seen : out)
        if (seen == item)
          throw Error(ErrorKind::Usage, flag,
                      inQuotes(item) + " is listed twice in " + inQuotes(text));
    out.push_back(std::move(item));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

void usageError(const std::string& app, const std::string& where, const std::string& message) {
  throw Error(ErrorKind::Usage, where, message + " (see " + app + " --help)");
}

bool Args::next() {
  if (++i_ >= argc_) return false;
  flag_ = argv_[i_];
  if (usage_ && (flag_ == "--help" || flag_ == "-h")) {
    std::fputs(usage_, stdout);
    std::exit(0);
  }
  return true;
}

bool parseCommonFlag(Args& a, CommonFlags& f, unsigned groups) {
  if ((groups & kSceneFlags) && a.is("--scene"))
    f.scene = a.value();
  else if ((groups & kSizeFlags) && a.is("--width"))
    f.width = uint32_t(a.integer(f.minSize, 16384));
  else if ((groups & kSizeFlags) && a.is("--height"))
    f.height = uint32_t(a.integer(f.minSize, 16384));
  else if ((groups & kEffectFlags) && a.is("--preset"))
    f.request.preset = a.value();
  else if ((groups & kEffectFlags) && a.is("--effects"))
    f.request.overrides.effects = a.effectList();  // a name twice is refused
  else if ((groups & kEffectFlags) && a.is("--set"))
    f.request.overrides.sets.push_back(a.value());
  else if ((groups & kEffectFlags) && a.is("--view"))
    f.request.view = a.value();
  else if ((groups & kDeviceFlags) && a.is("--device"))
    f.device = a.value();
  else if ((groups & kDeviceFlags) && a.is("--validation"))
    f.validation = true;
  else
    return false;
  return true;
}

void Args::unknown() const {
  usageError(app_, "", "unknown argument " + inQuotes(flag_));
}

const char* Args::value() {
  if (i_ + 1 >= argc_) fail("needs a value");
  return argv_[++i_];
}

double Args::number(double lo, double hi) {
  const std::string text = value();
  std::string problem;
  const auto v = parseDouble(text, &problem);
  const std::string range = rangeText('[', formatNumber(lo), formatNumber(hi));
  if (!v) fail("expects a number in " + range + ", got " + inQuotes(text) + ", which " + problem);
  if (!(*v >= lo && *v <= hi)) fail("expects a number in " + range + ", got " + inQuotes(text));
  return *v;
}

double Args::numberAbove(double lo, double hi) {
  const std::string text = value();
  std::string problem;
  const auto v = parseDouble(text, &problem);
  const std::string range = rangeText('(', formatNumber(lo), formatNumber(hi));
  if (!v) fail("expects a number in " + range + ", got " + inQuotes(text) + ", which " + problem);
  if (!(*v > lo && *v <= hi)) fail("expects a number in " + range + ", got " + inQuotes(text));
  return *v;
}

int64_t Args::integer(int64_t lo, int64_t hi) {
  const std::string text = value();
  std::string problem;
  const auto v = parseInteger(text, &problem);
  const std::string range = rangeText('[', std::to_string(lo), std::to_string(hi));
  if (!v) fail("expects an integer in " + range + ", got " + inQuotes(text) + ", which " + problem);
  if (*v < lo || *v > hi) fail("expects an integer in " + range + ", got " + inQuotes(text));
  return *v;
}

namespace {

// Creates and removes `probe` in `folder`: the only test that holds for root, read-only file
// systems and /proc alike.
void checkWritableFolder(const fs::path& folder, const std::string& path, const fs::path& probe) {
  std::error_code ec;
  const fs::path dir = folder.empty() ? fs::path(".") : folder;
  if (!fs::exists(dir, ec))
    throw Error(ErrorKind::FileNotFound, path, "output folder " + dir.string() + " does not exist");
  if (!fs::is_directory(dir, ec))
    throw Error(ErrorKind::Output, path, dir.string() + " is not a folder");
  const fs::path file = dir / probe;
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0 && errno != EEXIST)
    throw Error(ErrorKind::Output, path,
                "cannot write in the output folder " + dir.string() + ": " + std::strerror(errno));
  if (fd >= 0) {
    ::close(fd);
    ::unlink(file.c_str());
  }
}

}  // namespace

void checkOutputWritable(const std::string& path) {
  std::error_code ec;
  checkReplaceableOutput(path);  // a folder, device, FIFO or socket
  const fs::path folder = fs::path(path).parent_path();
  if (!folder.empty() && !fs::exists(folder, ec)) {
    // Made when the file is written (with its missing parents): the nearest existing
    // ancestor must take new entries.
    checkOutputFolder(folder.string());
    return;
  }
  checkWritableFolder(folder, path, fs::path(path).filename().string() + ".partial");
  if (fs::exists(path, ec) && ::access(path.c_str(), W_OK) != 0)
    throw Error(ErrorKind::Output, path, "output file exists and is not writable");
}

void checkOutputFolder(const std::string& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      throw Error(ErrorKind::Output, dir, "output path exists and is not a folder");
    checkWritableFolder(dir, dir, ".gi-write-check-" + std::to_string(::getpid()));
    return;
  }
  fs::path ancestor = fs::path(dir).parent_path();  // created with its missing parents
  while (!ancestor.empty() && !fs::exists(ancestor, ec)) ancestor = ancestor.parent_path();
  checkWritableFolder(ancestor, dir, ".gi-write-check-" + std::to_string(::getpid()));
}

void writeFileAtomic(const std::string& path, const std::string& text) {
  checkReplaceableOutput(path);
  const std::string tmp = path + ".partial";
  std::error_code ec;
  if (const fs::path folder = fs::path(path).parent_path(); !folder.empty())
    fs::create_directories(folder, ec);  // a failure shows as "cannot write" below
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.flush();
    if (!out) {
      fs::remove(tmp, ec);
      throw Error(ErrorKind::Output, path, "cannot write the file");
    }
  }
  try {
    checkReplaceableOutput(path);  // again: it may have appeared while the text was written
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(ErrorKind::Output, path, "cannot write the file: " + ec.message());
  }
}

}  // namespace gi::cli
