// What every gi-bench mode loads before it measures: the plugins, scenes and presets, the
// CPU references (cached on disk), the Vulkan context; small text helpers.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gi/effect_config.h"
#include "gi/effect_registry.h"
#include "gi/image_io.h"
#include "gi/scene.h"
#include "gi/vk/context.h"
#include "options.h"

namespace gi_bench {

struct Reference {
  gi::ImageRGBA32F value, depth;
  gi::ImageRGBA32F stdError;  // per-pixel standard error of value (rgb)
  gi::ImageRGBA32F split;     // ao-split only: AO_visible, f_off, f_hid (reference.h)
  uint32_t spp = 0;
  double meanStdError = 0.0, seconds = 0.0;
  bool cached = false;
};

struct ReferenceKey {
  size_t scene = 0;
  ReferenceSpec spec;  // quantity and every parameter it uses
  bool operator<(const ReferenceKey& o) const {
    return scene != o.scene ? scene < o.scene : spec < o.spec;
  }
};

struct LoadedScene {
  std::string name;  // as given
  gi::Scene scene;
  std::string contents;  // file bytes ("default" for the built-in scene)
};

struct Setup {
  gi::EffectRegistry registry;
  std::vector<LoadedScene> scenes;
  std::vector<std::unique_ptr<gi::Preset>> presets;  // nullptr entries: "none"
  std::vector<std::string> presetNames;              // as given, 'all' expanded
};

void loadInputs(const Options& o, Setup& s);
// The CPU reference of one key at `spp` samples (0: o.refSpp), from the cache (o.cache) or
// rendered and cached.
Reference computeReference(const Options& o, const LoadedScene& s, const ReferenceKey& k,
                           uint32_t spp = 0);
// Every key's reference (each once), with a progress bar.
std::map<ReferenceKey, Reference> computeReferences(const Options& o, const Setup& s,
                                                    const std::vector<ReferenceKey>& keys);
// --effects as effect sets ("a+b"), checked against the registry ("all": every effect alone).
std::vector<std::string> effectItems(const Options& o, const gi::EffectRegistry& registry);
std::vector<std::string> splitPlus(const std::string& item);  // "a+b" -> {a, b}; "none" -> {}
std::string joinList(const std::vector<std::string>& items);  // "a, b"
std::string knownEffects(const gi::EffectRegistry& registry);
gi::vk::Context makeContext(const Options& o);  // --device, --validation
std::string formatDouble(double v);             // %g
std::string nowString();                        // UTC

}  // namespace gi_bench
