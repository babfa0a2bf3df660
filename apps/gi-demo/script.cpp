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

// The range of each numeric argument (verb, argument index).
struct NumberRange {
  const char* verb;
  size_t arg;
  double lo, hi;
  bool integer;
};
const NumberRange kRanges[] = {
    {"frames", 0, 1, 100000, true},       // a script always ends
    {"key", 1, 1, 100000, true},          // frames held
    {"look", 0, -1e5, 1e5, false},        // pixels
    {"look", 1, -1e5, 1e5, false},        //
    {"camera", 0, -1e7, 1e7, false},      // world position
    {"camera", 1, -1e7, 1e7, false},      //
    {"camera", 2, -1e7, 1e7, false},      //
    {"camera", 3, -36000, 36000, false},  // yaw, degrees
    {"camera", 4, -90, 90, false},        // pitch, degrees
    {"resize", 0, 16, 16384, true},       // window size (the demo's smallest, Vulkan's largest)
    {"resize", 1, 16, 16384, true},       //
    {"time", 0, -1e9, 1e9, false},        // seconds
    {"accuracy", 1, 1, 1 << 16, true},    // samples per pixel
};

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
    // Numbers are checked now, so a bad script fails before any window opens; each has a range,
    // so a script always ends and never makes a non-finite camera or a window the screen
    // cannot have.
    for (const NumberRange& r : kRanges)
      if (r.verb == s.verb) {
        const double v = scriptNumber(s, r.arg, path);
        if (!(v >= r.lo && v <= r.hi) || (r.integer && v != std::floor(v)))
          fail(path, line,
               s.verb + ": argument " + std::to_string(r.arg + 1) + " expects " +
                   (r.integer ? "an integer" : "a number") + " in [" + gi::cli::formatNumber(r.lo) +
                   ", " + gi::cli::formatNumber(r.hi) + "], got '" + s.args[r.arg] + "'");
      }
    if ((s.verb == "effect" && s.args[1] != "on" && s.args[1] != "off") ||
        (s.verb == "pause" && s.args[0] != "on" && s.args[0] != "off"))
      fail(path, line, s.verb + ": expected on or off");
    if (s.verb == "print" && s.args[0] != "passes" && s.args[0] != "timings" &&
        s.args[0] != "memory" && s.args[0] != "camera" && s.args[0] != "views")
      fail(path, line, "print: expected passes, views, timings, memory or camera");
    steps.push_back(std::move(s));
  }
  // Without a step the demo would wait for a window close that a script run never gets.
  if (steps.empty()) throw gi::Error(gi::ErrorKind::Parse, path, "the script has no step");
  return steps;
}

}  // namespace demo
