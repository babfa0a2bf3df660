// Finds, loads and lists effect plugins. Each effect is a shared module (effects/<name>/)
// exporting two C functions (see GI_EFFECT_MODULE); the registry dlopen()s it, checks its ABI
// version and lets it register its effects. A rebuilt module can be loaded again
// (reloadModule). Loaded code stays mapped for the life of the process: effect instances made
// from an earlier version of a module may outlive its reload.
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
  // Loads the module at `path` (loaded before) again after it was rebuilt: a private copy of
  // the file is loaded, so the code of the previous version stays mapped and a file still being
  // written can never be mapped. The effects the new version registers replace the ones the
  // path registered before. On any failure (not a module, ABI mismatch, a registration that
  // throws, an invalid or duplicate effect) the registry is unchanged and the gi::Error names
  // `path`. Returns the names the module now registers. Effects already created keep running
  // their old code: create them again (Renderer::setEffects) to run the new one.
  std::vector<std::string> reloadModule(const std::string& path);
  // The module files loaded, as given to loadModule / found by a scan, in load order.
  std::vector<std::string> modulePaths() const;
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
  struct Module {
    std::string path, canonical;
  };
  // Opens `file` as a module (symbols, ABI version; errors name `path`) and registers what it
  // registers into a copy of the entries without `replaced`'s; commits only when all succeed.
  void openAndRegister(const std::string& file, const std::string& path,
                       const std::string& replaced);
  std::vector<Module> modules_;
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
