// Hot reload of effects' GLSL: watches the source files of every shader the loaded effect
// modules registered (gi/vk/shader_overrides.h), the files next to them and the engine's
// include folder. After a change it compiles the affected shaders again; only when all compile
// does it set them as overrides (the caller then re-creates the effects), so a compile error
// keeps the last good pipelines running.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "gi/vk/shader_overrides.h"

namespace demo {

class ShaderWatcher {
 public:
  // `overrideDir` (gi-demo --shader-dir): a registered shader whose file name exists there is
  // read from there instead of its source path. Takes the files' texts now as the baseline.
  explicit ShaderWatcher(std::string overrideDir = "");

  struct Result {
    std::vector<std::string> rebuilt;  // shader files compiled again (or back to their build)
    std::string error;                 // the compiler's message; nothing was changed
  };
  // Reads the watched files; after a change compiles the shaders it affects.
  Result poll();
  size_t watchedFiles() const { return texts_.size(); }

 private:
  std::string fileOf(const gi::vk::ShaderSource& s) const;
  std::map<std::string, std::string> readAll() const;

  std::string overrideDir_;
  std::vector<gi::vk::ShaderSource> sources_;
  std::vector<std::string> files_;                       // everything watched
  std::map<std::string, std::string> baseline_, texts_;  // file -> text (at start, last poll)
};

}  // namespace demo
