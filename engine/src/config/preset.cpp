// Quality presets: finding one by name, reading and checking its file (gi/effect_config.h).
// Kept apart from resolving effects so that the preset fuzzer (tests/fuzz) links only this.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

#include "gi/effect_config.h"
#include "gi/errors.h"
#include "gi/input_file.h"

namespace gi {

namespace fs = std::filesystem;
using nlohmann::json;

// A preset is a few hundred bytes; anything near this is not one.
constexpr uint64_t kMaxPresetBytes = 64ull << 20;

std::vector<std::string> presetLocations() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("GI_PRESET_PATH")) {
    std::stringstream ss(env);
    std::string d;
    while (std::getline(ss, d, ':'))
      if (!d.empty()) dirs.push_back(d);
  }
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back((exe.parent_path().parent_path() / "share" / "gi" / "presets").string());
  return dirs;
}

std::vector<std::string> presetNames() {
  std::set<std::string> names;
  for (const std::string& dir : presetLocations()) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".json" && e.is_regular_file(ec))
        names.insert(e.path().stem().string());
  }
  // The quality levels in their order, then the rest (device profiles) by name.
  const std::vector<std::string> levels = {"low", "medium", "high", "ultra"};
  std::vector<std::string> out;
  for (const std::string& l : levels)
    if (names.count(l)) out.push_back(l);
  for (const std::string& n : names)
    if (std::find(levels.begin(), levels.end(), n) == levels.end()) out.push_back(n);
  return out;
}

namespace {

std::string findPreset(const std::string& nameOrPath) {
  if (nameOrPath.find('/') != std::string::npos || fs::path(nameOrPath).extension() == ".json")
    return nameOrPath;
  std::string searched;
  for (const std::string& dir : presetLocations()) {
    fs::path p = fs::path(dir) / (nameOrPath + ".json");
    if (fs::exists(p)) return p.string();
    searched += " " + dir;
  }
  std::string known;
  for (const std::string& name : presetNames()) known += (known.empty() ? "" : ", ") + name;
  throw Error(ErrorKind::FileNotFound, nameOrPath + ".json",
              "no preset named '" + nameOrPath + "' (presets: " +
                  (known.empty() ? "none found" : known) + "; searched:" + searched + ")");
}

void onlyKeys(const json& j, const std::set<std::string>& allowed, const std::string& where,
              const std::string& file) {
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!allowed.count(it.key()))
      throw Error(ErrorKind::Schema, file,
                  (where.empty() ? "" : where + ".") + it.key() + ": unknown key");
}

}  // namespace

Preset loadPreset(const std::string& nameOrPath) {
  const std::string path = findPreset(nameOrPath);
  // Regular files only, size-limited: a directory or a FIFO is refused, not read.
  return parsePreset(readInputFile(path, "preset file", kMaxPresetBytes), path);
}

Preset parsePreset(std::string_view text, const std::string& path) {
  Preset p;
  p.path = path;
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw Error(ErrorKind::EmptyFile, p.path, "preset file is empty");
  const json j = parseJsonText(text, p.path);
  if (!j.is_object()) throw Error(ErrorKind::Schema, p.path, "a preset must be a JSON object");
  // "calibration": gi-bench --calibrate's record of its search (read by people, not here).
  onlyKeys(j,
           {"name", "description", "platform", "target_ms", "reference_resolution", "effects",
            "recommended_effects", "calibration"},
           "", p.path);
  if (j.contains("calibration") && !j["calibration"].is_object())
    throw Error(ErrorKind::Schema, p.path, "calibration: expected an object");
  auto str = [&](const char* key, std::string& out) {
    if (!j.contains(key)) return;
    if (!j[key].is_string())
      throw Error(ErrorKind::Schema, p.path, std::string(key) + ": expected a string");
    out = j[key];
  };
  str("name", p.name);
  str("description", p.description);
  str("platform", p.platform);
  if (p.name.empty()) p.name = fs::path(p.path).stem().string();
  if (j.contains("target_ms")) {
    if (!j["target_ms"].is_number() || j["target_ms"].get<double>() <= 0)
      throw Error(ErrorKind::Schema, p.path,
                  "target_ms: expected a positive number of milliseconds");
    p.targetMs = j["target_ms"];
  }
  if (j.contains("reference_resolution")) {
    const json& r = j["reference_resolution"];
    if (!r.is_array() || r.size() != 2 || !r[0].is_number_unsigned() ||
        !r[1].is_number_unsigned() || r[0] == 0 || r[1] == 0)
      throw Error(ErrorKind::Schema, p.path,
                  "reference_resolution: expected [width, height] (positive integers)");
    p.referenceWidth = r[0];
    p.referenceHeight = r[1];
  }
  if (j.contains("effects")) {
    if (!j["effects"].is_object())
      throw Error(ErrorKind::Schema, p.path, "effects: expected an object");
    for (auto it = j["effects"].begin(); it != j["effects"].end(); ++it) {
      if (!it.value().is_object())
        throw Error(ErrorKind::Schema, p.path,
                    "effects." + it.key() + ": expected an object of settings");
      p.effects[it.key()] = it.value();
    }
  }
  if (j.contains("recommended_effects")) {
    const json& r = j["recommended_effects"];
    if (!r.is_array() || r.empty())
      throw Error(ErrorKind::Schema, p.path,
                  "recommended_effects: expected a non-empty array of effect names");
    for (const json& name : r) {
      if (!name.is_string())
        throw Error(ErrorKind::Schema, p.path, "recommended_effects: expected effect names");
      p.recommendedEffects.push_back(name);
    }
  }
  return p;
}

}  // namespace gi
