#include "script.h"

#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>

#include "cli.h"
#include "gi/errors.h"
#include "gi/input_file.h"

namespace demo {

namespace {

// Verb -> argument count (-1: one or more).
const std::map<std::string, int> kVerbs = {
    {"frames", 1}, {"key", 2},        {"look", 2},   {"camera", 5}, {"effect", 2}, {"set", 1},
    {"preset", 1}, {"view", 1},       {"resize", 2}, {"pause", 1},  {"step", 0},   {"accuracy", 2},
    {"time", 1},   {"screenshot", 1}, {"print", 1},  {"reload", 0}, {"copy", 2}};

[[noreturn]] void fail(const std::string& path, int line, const std::string& what) {
  throw gi::Error(gi::ErrorKind::Parse, path, "line " + std::to_string(line) + ": " + what);
}

}  // namespace

double scriptNumber(const ScriptStep& step, size_t arg, const std::string& path) {
  const std::string& text = step.args.at(arg);
  std::string problem;  // decimal and finite, as every command-line number (cli.h)
  const std::optional<double> v = gi::cli::parseDouble(text, &problem);
  if (!v)
    fail(path, step.line, step.verb + ": expected a number, got '" + text + "', which " + problem);
  return *v;
}

std::vector<ScriptStep> loadScript(const std::string& path) {
  // Regular files only, size-limited (gi/input_file.h): a FIFO is refused, not waited on.
  std::istringstream in(gi::readInputFile(path, "script file", 64ull << 20));
  std::vector<ScriptStep> steps;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    if (const size_t hash = text.find('#'); hash != std::string::npos) text.resize(hash);
    std::istringstream words(text);
    ScriptStep s;
    s.line = line;
    if (!(words >> s.verb)) continue;
    for (std::string w; words >> w;) s.args.push_back(w);
    const auto verb = kVerbs.find(s.verb);
    if (verb == kVerbs.end()) {
      std::string known;
      for (const auto& [name, count] : kVerbs) known += (known.empty() ? "" : ", ") + name;
      fail(path, line, "unknown step '" + s.verb + "' (steps: " + known + ")");
    }
    if (int(s.args.size()) != verb->second)
      fail(path, line,
           s.verb + " takes " + std::to_string(verb->second) + " argument(s), got " +
               std::to_string(s.args.size()));
    // Numbers are checked now, so a bad script fails before any window opens.
    const std::map<std::string, std::vector<size_t>> numeric = {
        {"frames", {0}},    {"key", {1}},  {"look", {0, 1}}, {"camera", {0, 1, 2, 3, 4}},
        {"resize", {0, 1}}, {"time", {0}}, {"accuracy", {1}}};
    if (auto n = numeric.find(s.verb); n != numeric.end())
      for (size_t i : n->second) scriptNumber(s, i, path);
    if ((s.verb == "effect" && s.args[1] != "on" && s.args[1] != "off") ||
        (s.verb == "pause" && s.args[0] != "on" && s.args[0] != "off"))
      fail(path, line, s.verb + ": expected on or off");
    if (s.verb == "print" && s.args[0] != "passes" && s.args[0] != "timings" &&
        s.args[0] != "memory" && s.args[0] != "camera" && s.args[0] != "views")
      fail(path, line, "print: expected passes, views, timings, memory or camera");
    steps.push_back(std::move(s));
  }
  return steps;
}

}  // namespace demo
