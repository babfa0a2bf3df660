// Finds, loads and lists effect plugins. Each effect is a shared module (effects/<name>/)
// exporting two C functions (see GI_EFFECT_MODULE); the registry dlopen()s it, checks its ABI
// version and lets it register its effects. Modules stay loaded for the life of the process.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gi/effect_info.h"

namespace gi {

class EffectRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Effect>()>;

  // Registers an effect; refuses (throws gi::Error) an invalid info or a duplicate name.
  void add(const Factory& factory, const std::string& origin = "built-in");
  // Loads one module; throws gi::Error naming the file on failure (not a module, ABI
  // mismatch, duplicate effect).
  void loadModule(const std::string& path);
  // Loads every *.so in `dir`; a refused module is reported in problems() and on stderr, the
  // others still load. A missing folder is skipped.
  void scanDirectory(const std::string& dir);
  // <executable dir>/plugins, then each folder of GI_PLUGIN_PATH (':'-separated).
  void scanDefaultLocations();
  static std::vector<std::string> defaultLocations();

  bool has(const std::string& name) const;
  std::vector<std::string> names() const;  // sorted
  const EffectInfo& info(const std::string& name) const;
  std::string origin(const std::string& name) const;  // module path or "built-in"
  // A fresh instance; throws gi::Error(Schema) naming the unknown effect and the known ones.
  std::unique_ptr<Effect> create(const std::string& name) const;
  // Default settings of an effect.
  SettingValues defaultSettings(const std::string& name) const;
  const std::vector<std::string>& problems() const { return problems_; }
  // Human-readable list: each effect with its settings, defaults, ranges and help.
  std::string describe() const;

 private:
  struct Entry {
    EffectInfo info;
    std::vector<SettingDesc> settings;
    Factory factory;
    std::string origin;
  };
  const Entry& entry(const std::string& name) const;
  std::string origin_or(const std::string& name) const;
  std::vector<Entry> entries_;
  std::vector<std::string> problems_;
  std::vector<std::string> loadedPaths_;
};

}  // namespace gi

// Module entry points, looked up by the registry with dlsym.
extern "C" {
using GiEffectAbiVersionFn = uint32_t (*)();
using GiRegisterEffectsFn = void (*)(gi::EffectRegistry&);
}

// Defines the entry points of a module registering the listed Effect classes:
//   GI_EFFECT_MODULE(SsaoEffect)
#define GI_EFFECT_MODULE(...)                                                          \
  extern "C" __attribute__((visibility("default"))) uint32_t gi_effect_abi_version() { \
    return GI_EFFECT_ABI_VERSION;                                                      \
  }                                                                                    \
  extern "C" __attribute__((visibility("default"))) void gi_register_effects(          \
      gi::EffectRegistry& registry) {                                                  \
    gi::detail::registerAll<__VA_ARGS__>(registry);                                    \
  }

namespace gi::detail {
template <class... Effects>
void registerAll(EffectRegistry& registry) {
  (registry.add([] { return std::unique_ptr<Effect>(new Effects()); }), ...);
}
}  // namespace gi::detail
