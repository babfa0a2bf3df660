#include "controller.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "gi/engine_settings.h"
#include "gi/errors.h"
#include "preview.h"

namespace demo {

Controller::Controller(gi::vk::Context& ctx, const gi::Scene& scene,
                       const gi::EffectRegistry& registry, const ControllerOptions& options)
    : scene_(scene), registry_(registry), overrides_(options.request.overrides) {
  std::optional<gi::Preset> preset;
  if (!options.request.preset.empty()) preset = gi::loadPreset(options.request.preset);
  preset_ = options.request.preset;
  // The effects asked for (scene or --effects) are on, in their order; the others follow.
  for (const gi::EffectConfig& c :
       gi::resolveEffects(scene_, preset ? &*preset : nullptr, overrides_, registry_)) {
    order_.push_back(c.name);
    enabled_[c.name] = true;
  }
  for (const std::string& name : registry_.names())
    if (!enabled_.count(name)) {
      order_.push_back(name);
      enabled_[name] = false;
    }
  resolve(preset ? &*preset : nullptr);
  view_ = gi::resolveView(registry_, options.request.view);

  gi::RenderSettings s;
  gi::applyEngineSettings(values_.at(gi::kEngineSettingsOwner), s);
  s.width = options.width;
  s.height = options.height;
  s.view = view_;
  // What the accuracy check reads from the current frame (accuracy.cpp).
  s.keepForReadback = {gi::resources::kAO, gi::resources::kLit, gi::resources::kDepth};
  s.effects = configs();
  renderer_.emplace(ctx, scene_, s, &registry_);
}

void Controller::resolve(const gi::Preset* preset) {
  gi::EffectOverrides all = overrides_;
  all.effects = order_;
  for (gi::EffectConfig& c : gi::resolveEffects(scene_, preset, all, registry_))
    values_[c.name] = std::move(c.settings);
  values_[gi::kEngineSettingsOwner] =
      gi::resolveEngineSettings(scene_, preset, overrides_, gi::RenderSettings{});
}

std::vector<gi::EffectConfig> Controller::configs() const {
  std::vector<gi::EffectConfig> out;
  for (const std::string& name : order_)
    if (enabled_.at(name)) out.push_back({name, values_.at(name)});
  return out;
}

template <class Change>
bool Controller::attempt(Change&& change) {
  try {
    change();
    error_.clear();
    return true;
  } catch (const std::exception& e) {
    error_ = e.what();
    return false;
  }
}

bool Controller::enabled(const std::string& effect) const {
  auto it = enabled_.find(effect);
  return it != enabled_.end() && it->second;
}

bool Controller::setEnabled(const std::string& effect, bool on) {
  return attempt([&] {
    registry_.info(effect);  // unknown: names the known ones
    const bool was = enabled_.at(effect);
    enabled_[effect] = on;
    try {
      renderer_->setEffects(configs());
    } catch (...) {
      enabled_[effect] = was;  // the renderer kept its previous configuration
      throw;
    }
  });
}

bool Controller::turnOffFailed(const gi::EffectError& failure) {
  const std::string& effect = failure.effect();
  if (!enabled(effect)) return false;
  // Its debug view goes with it.
  if (view_ != gi::resources::kOutput && registry_.has(effect) &&
      (view_ == effect || view_ == registry_.info(effect).debugView))
    setView(gi::resources::kOutput);
  if (!setEnabled(effect, false)) return false;
  error_ = std::string(failure.what()) + " (turned off)";
  return true;
}

bool Controller::reloadEffects() {
  return attempt([&] {
    // Without its effects the renderer cannot show an effect's output: the view waits outside.
    const bool away = view_ != gi::resources::kOutput;
    if (away) renderer_->setView(gi::resources::kOutput);
    renderer_->setEffects({});
    renderer_->setEffects(configs());
    if (away) renderer_->setView(view_);
  });
}

bool Controller::adoptReloadedModule(const std::vector<std::string>& effects,
                                     std::vector<std::string>* kept) {
  const auto oldOrder = order_;
  const auto oldEnabled = enabled_;
  const auto oldValues = values_;
  std::vector<std::string> carried;
  for (const std::string& name : effects) {
    gi::SettingValues next = registry_.defaultSettings(name);
    if (auto it = values_.find(name); it != values_.end())
      for (const std::string& key : next.adopt(it->second)) carried.push_back(name + "." + key);
    else {
      order_.push_back(name);
      enabled_[name] = false;
    }
    values_[name] = std::move(next);
  }
  std::erase_if(order_, [&](const std::string& name) {
    if (registry_.has(name)) return false;
    enabled_.erase(name);
    values_.erase(name);
    return true;
  });
  if (reloadEffects()) {
    if (kept) *kept = std::move(carried);
    return true;
  }
  order_ = oldOrder;
  enabled_ = oldEnabled;
  values_ = oldValues;
  return false;
}

const gi::SettingValues& Controller::settings(const std::string& owner) const {
  auto it = values_.find(owner);
  if (it == values_.end())
    throw gi::Error(gi::ErrorKind::Usage, "", "no settings named '" + owner + "'");
  return it->second;
}

bool Controller::setSetting(const std::string& owner, const std::string& key,
                            const nlohmann::json& value) {
  return attempt([&] {
    gi::SettingValues next = settings(owner);
    next.set(key, value, "gi-demo");
    if (owner == gi::kEngineSettingsOwner) {
      gi::RenderSettings s = renderer_->settings();
      gi::applyEngineSettings(next, s);
      renderer_->applySettings(s);
    } else if (enabled(owner)) {
      renderer_->setEffectSettings(owner, next);
    }
    values_[owner] = std::move(next);
  });
}

bool Controller::setFromString(const std::string& assignment) {
  const size_t dot = assignment.find('.'), eq = assignment.find('=');
  if (dot == std::string::npos || eq == std::string::npos || eq < dot) {
    error_ = "expected OWNER.KEY=VALUE, got '" + assignment + "'";
    return false;
  }
  const std::string owner = assignment.substr(0, dot),
                    key = assignment.substr(dot + 1, eq - dot - 1);
  gi::SettingValues parsed;
  if (!attempt([&] {
        parsed = settings(owner);
        parsed.setFromString(key, assignment.substr(eq + 1), "gi-demo");
      }))
    return false;
  const gi::SettingDesc& d = parsed.desc(key);
  using T = gi::SettingType;
  if (d.type == T::Vec3 || d.type == T::Color) {
    const auto v = parsed.vector(key);
    return setSetting(owner, key, nlohmann::json::array({v[0], v[1], v[2]}));
  }
  if (d.type == T::Enum) return setSetting(owner, key, parsed.option(key));
  if (d.type == T::Bool) return setSetting(owner, key, parsed.flag(key));
  if (d.type == T::Int) return setSetting(owner, key, parsed.integer(key));
  return setSetting(owner, key, parsed.number(key));
}

std::vector<std::string> Controller::presets() const {
  std::vector<std::string> names;
  std::error_code ec;
  for (const std::string& dir : gi::presetLocations())
    for (const auto& e : std::filesystem::directory_iterator(dir, ec))
      if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

bool Controller::setPreset(const std::string& nameOrPath) {
  return attempt([&] {
    std::optional<gi::Preset> preset;
    if (!nameOrPath.empty()) preset = gi::loadPreset(nameOrPath);
    const auto oldValues = values_;
    resolve(preset ? &*preset : nullptr);
    try {
      gi::RenderSettings s = renderer_->settings();
      gi::applyEngineSettings(values_.at(gi::kEngineSettingsOwner), s);
      s.effects = configs();
      renderer_->applySettings(s);
    } catch (...) {
      values_ = oldValues;
      throw;
    }
    preset_ = nameOrPath;
  });
}

bool Controller::setView(const std::string& view) {
  return attempt([&] {
    const std::string resource = gi::resolveView(registry_, view);
    renderer_->setView(resource);
    view_ = resource;
  });
}

bool Controller::resize(uint32_t width, uint32_t height) {
  return attempt([&] {
    gi::RenderSettings s = renderer_->settings();
    s.width = width;
    s.height = height;
    renderer_->applySettings(s);
  });
}

gi::ImageRGBA8 Controller::image() {
  if (view_ == gi::resources::kOutput) return renderer_->readOutput();
  return gi::app::previewOf(renderer_->readTarget(view_), view_);
}

}  // namespace demo
