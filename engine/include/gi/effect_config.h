// Which effects a frame runs and with which settings: registry defaults < quality preset <
// the scene's overrides < command line (--set effect.key=value). Every layer is validated
// against the effects' declared settings; errors name the file (or flag), the key and the range.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gi/effect_registry.h"
#include "gi/renderer.h"
#include "gi/scene.h"

namespace gi {

// A quality preset (assets/presets/*.json), in the spirit of Alchemy's platform profiles.
struct Preset {
  std::string path;
  std::string name, description, platform;
  double targetMs = 0.0;                             // frame budget the preset aims at ...
  uint32_t referenceWidth = 0, referenceHeight = 0;  // ... at this resolution
  std::map<std::string, nlohmann::json> effects;     // effect -> {setting: value}
};

// Folders searched for presets by name: $GI_PRESET_PATH (':'-separated), then
// <executable dir>/../share/gi/presets (the build tree and installs both have it).
std::vector<std::string> presetLocations();
// `nameOrPath`: a preset name ("medium") or a .json path. Throws gi::Error naming the file.
Preset loadPreset(const std::string& nameOrPath);
// Checks every effect and setting a preset names against the registry.
void validatePreset(const Preset& preset, const EffectRegistry& registry);

struct EffectOverrides {
  std::optional<std::vector<std::string>> effects;  // --effects (replaces the scene's list)
  std::vector<std::string> sets;                    // --set effect.key=value, in order
};

// Parses "a,b,c" ("" -> empty list).
std::vector<std::string> splitEffectList(const std::string& text);

std::vector<EffectConfig> resolveEffects(const Scene& scene, const Preset* preset,
                                         const EffectOverrides& cli,
                                         const EffectRegistry& registry);

}  // namespace gi
