#include "gi/effect_config.h"

#include <algorithm>
#include <sstream>

#include "gi/engine_settings.h"
#include "gi/errors.h"

namespace gi {

using nlohmann::json;

namespace {

bool isEngine(const std::string& name) {
  return name == kEngineSettingsOwner;
}

void applyJson(SettingValues& s, const json& values, const std::string& origin) {
  for (auto it = values.begin(); it != values.end(); ++it) s.set(it.key(), it.value(), origin);
}

// A preset is written for no scene in particular: its world lengths, like the defaults, are
// for the reference scene size and follow Scene::lengthScale (clamped to their range). Scene
// files and --set give lengths in the scene's own units and are taken as they are.
void applyPresetJson(SettingValues& s, const json& values, const std::string& origin,
                     float lengthScale) {
  applyJson(s, values, origin);
  if (lengthScale == 1.0f) return;
  for (const SettingDesc& d : s.descs())
    if (d.worldLength && d.type == SettingType::Float && values.contains(d.name))
      s.set(d.name, std::clamp(s.number(d.name) * lengthScale, d.minValue, d.maxValue), origin);
}

struct SetArg {
  std::string owner, key, value;
};

// "effect.key=value" (or "engine.key=value").
SetArg parseSet(const std::string& s) {
  const size_t dot = s.find('.'), eq = s.find('=');
  if (dot == std::string::npos || eq == std::string::npos || dot > eq)
    throw Error(ErrorKind::Usage, "--set", "'" + s + "': expected effect.setting=value");
  return {s.substr(0, dot), s.substr(dot + 1, eq - dot - 1), s.substr(eq + 1)};
}

// Layers the engine's values: preset < scene < --set, each validated with its origin.
void layerEngineSettings(SettingValues& v, const Scene& scene, const Preset* preset,
                         const EffectOverrides& cli) {
  if (preset && preset->effects.count(kEngineSettingsOwner))
    applyPresetJson(v, preset->effects.at(kEngineSettingsOwner), preset->path, scene.lengthScale);
  for (const EffectRequest& r : scene.effects)
    if (isEngine(r.name)) applyJson(v, r.settings, scene.sourcePath);
  for (const std::string& s : cli.sets) {
    const SetArg a = parseSet(s);
    if (isEngine(a.owner)) v.setFromString(a.key, a.value, "--set");
  }
}

}  // namespace

void validatePreset(const Preset& preset, const EffectRegistry& registry) {
  for (const std::string& name : preset.recommendedEffects) {
    if (isEngine(name))
      throw Error(ErrorKind::Schema, preset.path, "recommended_effects: 'engine' is no effect");
    try {
      registry.info(name);
    } catch (const Error& e) {
      throw Error(ErrorKind::Schema, preset.path, std::string("recommended_effects: ") + e.what());
    }
  }
  for (const auto& [effect, values] : preset.effects) {
    if (isEngine(effect)) {
      SettingValues s(kEngineSettingsOwner, engineSettingDescs());
      applyJson(s, values, preset.path);
      continue;
    }
    if (!registry.has(effect)) {
      try {
        registry.info(effect);
      } catch (const Error& e) {
        throw Error(ErrorKind::Schema, preset.path, "effects." + effect + ": " + e.what());
      }
    }
    SettingValues s = registry.defaultSettings(effect);
    applyJson(s, values, preset.path);
  }
}

std::vector<std::string> splitEffectList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// World-length defaults follow the scene's size (Scene::lengthScale), clamped to their range.
static void scaleWorldLengths(SettingValues& values, float lengthScale) {
  if (lengthScale == 1.0f) return;
  for (const SettingDesc& d : values.descs())
    if (d.worldLength && d.type == SettingType::Float)
      values.set(d.name, std::clamp(d.defaultValue * lengthScale, d.minValue, d.maxValue),
                 "the model's size");
}

std::vector<EffectConfig> resolveEffects(const Scene& scene, const Preset* preset,
                                         const EffectOverrides& cli,
                                         const EffectRegistry& registry) {
  std::vector<std::string> names;
  if (cli.effects && *cli.effects == std::vector<std::string>{"recommended"}) {
    if (!preset)
      throw Error(ErrorKind::Usage, "--effects",
                  "'recommended' runs a preset's recommended effects: give --preset");
    if (preset->recommendedEffects.empty())
      throw Error(ErrorKind::Usage, preset->path,
                  "preset '" + preset->name + "' recommends no effects (recommended_effects)");
    names = preset->recommendedEffects;
  } else if (cli.effects) {
    names = *cli.effects;
    for (const std::string& name : names)
      if (isEngine(name))
        throw Error(ErrorKind::Usage, "--effects",
                    "'engine' names the engine's own settings, not an effect (set them with "
                    "--set engine.key=value)");
  } else {
    for (const EffectRequest& r : scene.effects)
      if (!isEngine(r.name)) names.push_back(r.name);
  }
  std::vector<EffectConfig> configs;
  for (const std::string& name : names) {
    if (std::any_of(configs.begin(), configs.end(),
                    [&](const EffectConfig& c) { return c.name == name; }))
      throw Error(ErrorKind::Schema, cli.effects ? "--effects" : scene.sourcePath,
                  "effect '" + name + "' listed twice");
    try {
      configs.push_back({name, registry.defaultSettings(name)});
    } catch (const Error& e) {
      throw Error(e.kind(), cli.effects ? "--effects" : scene.sourcePath, e.what());
    }
    scaleWorldLengths(configs.back().settings, scene.lengthScale);
  }
  if (preset) validatePreset(*preset, registry);
  // The engine's entries, checked here too so a caller that skips resolveEngineSettings
  // still refuses them.
  SettingValues engine(kEngineSettingsOwner, engineSettingDescs());
  layerEngineSettings(engine, scene, preset, cli);
  for (EffectConfig& c : configs) {
    if (preset && preset->effects.count(c.name))
      applyPresetJson(c.settings, preset->effects.at(c.name), preset->path, scene.lengthScale);
    for (const EffectRequest& r : scene.effects)
      if (r.name == c.name) applyJson(c.settings, r.settings, scene.sourcePath);
  }
  for (const std::string& s : cli.sets) {
    const SetArg a = parseSet(s);
    if (isEngine(a.owner)) continue;
    auto it = std::find_if(configs.begin(), configs.end(),
                           [&](const EffectConfig& c) { return c.name == a.owner; });
    if (it == configs.end()) {
      registry.info(a.owner);  // unknown effect: names the known ones
      throw Error(ErrorKind::Usage, "--set",
                  "'" + s + "': effect '" + a.owner + "' is not enabled (scene or --effects)");
    }
    it->settings.setFromString(a.key, a.value, "--set");
  }
  return configs;
}

SettingValues resolveEngineSettings(const Scene& scene, const Preset* preset,
                                    const EffectOverrides& cli, const RenderSettings& base) {
  SettingValues v = engineSettingsOf(base);
  layerEngineSettings(v, scene, preset, cli);
  return v;
}

RenderSettings configureRender(const Scene& scene, const EffectRegistry& registry,
                               const Preset* preset, const RenderRequest& request,
                               RenderSettings base) {
  base.effects = resolveEffects(scene, preset, request.overrides, registry);
  applyEngineSettings(resolveEngineSettings(scene, preset, request.overrides, base), base);
  base.view = resolveView(registry, request.view);
  return base;
}

RenderSettings configureRender(const Scene& scene, const EffectRegistry& registry,
                               const RenderRequest& request, RenderSettings base) {
  std::optional<Preset> preset;
  if (!request.preset.empty()) preset = loadPreset(request.preset);  // checked by resolveEffects
  return configureRender(scene, registry, preset ? &*preset : nullptr, request, std::move(base));
}

std::string resolveView(const EffectRegistry& registry, const std::string& view) {
  return registry.has(view) ? registry.info(view).debugView : view;
}

}  // namespace gi
