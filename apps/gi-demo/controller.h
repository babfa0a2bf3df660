// What the panel and the script change, in one place: the effects switched on, every effect's
// and the engine's settings, the preset, the view, the size. Each change goes to the live
// renderer (Renderer::setEffects / setEffectSettings / applySettings / setView); a change the
// renderer refuses leaves everything as it was and is kept in lastError().
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gi/effect_config.h"
#include "gi/effect_registry.h"
#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene.h"

namespace demo {

struct ControllerOptions {
  // The preset (name or file; empty: none), --effects and --set (kept across preset switches),
  // the view (a resource name or an effect's name: its debug view).
  gi::RenderRequest request;
  uint32_t width = 1280, height = 720;
};

class Controller {
 public:
  // `scene` and `registry` must outlive the controller.
  Controller(gi::vk::Context& ctx, const gi::Scene& scene, const gi::EffectRegistry& registry,
             const ControllerOptions& options);

  gi::Renderer& renderer() { return *renderer_; }
  const gi::EffectRegistry& registry() const { return registry_; }

  // Every registered effect: the enabled-at-start ones in their order, then the others.
  const std::vector<std::string>& effects() const { return order_; }
  bool enabled(const std::string& effect) const;
  bool setEnabled(const std::string& effect, bool on);
  // An effect whose code failed while a frame rendered (`failure` names it): turned off, with
  // the failure kept as lastError() for the panel. False when it could not be turned off.
  bool turnOffFailed(const gi::EffectError& failure);
  // Settings of an effect or of the engine (gi::kEngineSettingsOwner).
  const gi::SettingValues& settings(const std::string& owner) const;
  bool setSetting(const std::string& owner, const std::string& key, const nlohmann::json& value);
  // "owner.key=value", as gi-render --set.
  bool setFromString(const std::string& assignment);

  // Preset files found where gi-render looks (gi::presetLocations()), by name.
  std::vector<std::string> presets() const;
  const std::string& preset() const { return preset_; }
  bool setPreset(const std::string& nameOrPath);  // "" for none

  const std::string& view() const { return view_; }
  bool setView(const std::string& view);  // a resource, or an effect's name
  bool resize(uint32_t width, uint32_t height);
  // Re-creates the effects that are on, as switching them off and on does: their pipelines are
  // built again (from hot-reloaded shaders, gi/vk/shader_overrides.h).
  bool reloadEffects();
  // After the registry reloaded a module that now registers `effects`: each one's settings
  // start from its new declaration and keep the values that still fit it
  // (gi::SettingValues::adopt); effects the registry no longer has are dropped, new ones are
  // listed (off); then the effects are re-created. False (lastError()) when that fails: the
  // settings are back as they were and the caller restores the registry. `kept` receives
  // "effect.key" for every value carried over.
  bool adoptReloadedModule(const std::vector<std::string>& effects,
                           std::vector<std::string>* kept = nullptr);

  // The image the window shows: the output, or a preview of the viewed resource (RGBA8).
  gi::ImageRGBA8 image();
  const std::string& lastError() const { return error_; }

 private:
  std::vector<gi::EffectConfig> configs() const;
  void resolve(const gi::Preset* preset);  // values_ from defaults, preset, scene, --set
  template <class Change>
  bool attempt(Change&& change);

  const gi::Scene& scene_;
  const gi::EffectRegistry& registry_;
  gi::EffectOverrides overrides_;
  std::vector<std::string> order_;
  std::map<std::string, bool> enabled_;
  std::map<std::string, gi::SettingValues> values_;  // every effect's, and "engine"
  std::string preset_, view_ = "output", error_;
  std::optional<gi::Renderer> renderer_;
};

}  // namespace demo
