// What the gi-bench end-to-end tests share: the command line, reading outputs back, CSV cells.
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"

namespace gi::test {

// gi-bench with validation on and no progress bar, followed by `args`.
inline std::string benchCommand(const std::string& args) {
  return binPath("gi-bench") + " --validation --no-progress " + args;
}

inline std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// One CSV line's cells ("quoted, cells" keep their commas; the quotes are dropped).
inline std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (c == ',' && !quoted)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

}  // namespace gi::test
