#include "module_watcher.h"

namespace demo {

ModuleWatcher::ModuleWatcher(const std::vector<std::string>& modules) {
  for (const std::string& m : modules) baseline_[m] = last_[m] = stampOf(m);
}

ModuleWatcher::Stamp ModuleWatcher::stampOf(const std::string& file) {
  std::error_code ec;
  Stamp s;
  s.exists = std::filesystem::is_regular_file(file, ec);
  if (!s.exists) return s;
  s.time = std::filesystem::last_write_time(file, ec);
  s.size = std::filesystem::file_size(file, ec);
  return s;
}

std::vector<std::string> ModuleWatcher::poll(bool settled) {
  std::vector<std::string> changed;
  for (auto& [module, last] : last_) {
    const Stamp now = stampOf(module);
    const bool steady = now == last;
    last = now;
    // A missing file (mid-build) is no module yet: wait for it.
    if (now.exists && !(now == baseline_.at(module)) && (steady || !settled))
      changed.push_back(module);
  }
  return changed;
}

void ModuleWatcher::accept(const std::string& module) {
  baseline_[module] = last_[module] = stampOf(module);
}

}  // namespace demo
