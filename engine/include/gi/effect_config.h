// Which effects a frame runs and with which settings: registry defaults < quality preset <
// the scene's overrides < command line (--set effect.key=value). Every layer is validated
// against the effects' declared settings; errors name the file (or flag), the key and the range.
// The engine's own settings (gi/engine_settings.h) travel the same way under the name "engine"
// (preset: "effects": {"engine": {...}}; scene: "effects": [{"name": "engine", "settings":
// {...}}]; --set engine.key=value); "engine" is never an effect. World lengths
// (SettingDesc::worldLength) in a preset are for the reference scene size, like the defaults:
// a model loaded without a scene file scales both by Scene::lengthScale.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "gi/effect_registry.h"
#include "gi/render_settings.h"
#include "gi/scene.h"

namespace gi {

// A quality preset (assets/presets/*.json), in the spirit of Alchemy's platform profiles.
struct Preset {
  std::string path;
  std::string name, description, platform;
  double targetMs = 0.0;                             // frame budget the preset aims at ...
  uint32_t referenceWidth = 0, referenceHeight = 0;  // ... at this resolution
  std::map<std::string, nlohmann::json> effects;     // effect (or "engine") -> {setting: value}
  // The effects this profile recommends running together ("recommended_effects"), chosen by
  // their measured error on the benchmark scenes; `--effects recommended` runs them.
  std::vector<std::string> recommendedEffects;
};

// Folders searched for presets by name: $GI_PRESET_PATH (':'-separated), then
// <executable dir>/../share/gi/presets (the build tree and installs both have it).
std::vector<std::string> presetLocations();
// The names of every preset found there (an earlier folder's file hides a later one's of the
// same name): the quality levels low, medium, high, ultra in that order, then the others by
// name.
std::vector<std::string> presetNames();
// `nameOrPath`: a preset name ("medium") or a .json path. Throws gi::Error naming the file.
Preset loadPreset(const std::string& nameOrPath);
// The preset in `text` (the contents of the file `path`, named in errors); what loadPreset
// does after reading the file.
Preset parsePreset(std::string_view text, const std::string& path);
// Checks every effect and setting a preset names against the registry ("engine": against the
// engine's settings).
void validatePreset(const Preset& preset, const EffectRegistry& registry);

struct EffectOverrides {
  // --effects (replaces the scene's list); the single name "recommended" stands for the
  // preset's recommendedEffects.
  std::optional<std::vector<std::string>> effects;
  std::vector<std::string> sets;  // --set effect.key=value (or engine.key=value), in order
};

// Parses "a,b,c" ("" -> empty list).
std::vector<std::string> splitEffectList(const std::string& text);

// The effects to run with their settings. Also validates the "engine" entries of the preset,
// scene and --set (their values come from resolveEngineSettings).
std::vector<EffectConfig> resolveEffects(const Scene& scene, const Preset* preset,
                                         const EffectOverrides& cli,
                                         const EffectRegistry& registry);

// The engine's settings: `base`'s values < the preset's "engine" < the scene's "engine"
// entries < --set engine.key=value (in order). Apply them with applyEngineSettings.
SettingValues resolveEngineSettings(const Scene& scene, const Preset* preset,
                                    const EffectOverrides& cli, const RenderSettings& base);

// What an app or a test asks of a frame besides its scene: a preset, the command line's effect
// list and --set assignments, and a view (a resource, or an effect's name for its debug view).
struct RenderRequest {
  std::string preset;  // a name or a .json path; empty: none
  EffectOverrides overrides;
  std::string view = "output";
};

// The one set-up path of every app and test fixture: the preset (loaded and checked against the
// registry), the effects with their settings (resolveEffects), the engine settings
// (resolveEngineSettings over `base`, applied), the view resolved (resolveView). The rest of
// `base` (size, floor pass, timing, read-back) is kept. Throws gi::Error naming the file or flag.
RenderSettings configureRender(const Scene& scene, const EffectRegistry& registry,
                               const RenderRequest& request, RenderSettings base = {});
// The same with a preset already loaded (gi-bench loads each once for many scenes); nullptr:
// none. request.preset is ignored.
RenderSettings configureRender(const Scene& scene, const EffectRegistry& registry,
                               const Preset* preset, const RenderRequest& request,
                               RenderSettings base = {});
// An effect's name stands for its debug view (EffectInfo::debugView); any other name is a
// resource's and is returned as it is.
std::string resolveView(const EffectRegistry& registry, const std::string& view);

}  // namespace gi
