// Hot reload of effect plugins: watches the module files the registry loaded and reports the
// ones rebuilt since the last reload (gi::EffectRegistry::reloadModule loads them again).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace demo {

class ModuleWatcher {
 public:
  // Takes the files' current state as the baseline.
  explicit ModuleWatcher(const std::vector<std::string>& modules);
  // The modules whose file changed since the baseline. `settled`: only those whose file has
  // not changed since the previous poll as well (a build may still be writing it).
  std::vector<std::string> poll(bool settled);
  // The module's current file becomes its baseline (after a reload, failed or not: a broken
  // build is reported once, not at every poll).
  void accept(const std::string& module);

 private:
  struct Stamp {
    std::filesystem::file_time_type time{};
    uintmax_t size = 0;
    bool exists = false;
    bool operator==(const Stamp&) const = default;
  };
  static Stamp stampOf(const std::string& file);
  std::map<std::string, Stamp> baseline_, last_;
};

}  // namespace demo
