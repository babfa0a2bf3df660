// What the fuzz targets share: the loaders take paths, so each input is written to a file in a
// private folder and loaded from there. The property checked: a loader either returns a scene
// or throws gi::Error; anything else (a crash, a sanitizer report, another exception, a hang)
// is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "gi/errors.h"

namespace gi::fuzz {

// A folder of this process's own (removed at exit).
inline const std::filesystem::path& workDir() {
  static const std::filesystem::path dir = [] {
    std::filesystem::path d =
        std::filesystem::temp_directory_path() / ("gi-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(workDir(), ec);
    });
    return d;
  }();
  return dir;
}

// Writes `bytes` to `name` in the work folder; returns its path.
inline std::string writeInput(const std::string& name, std::string_view bytes) {
  const std::string path = (workDir() / name).string();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), std::streamsize(bytes.size()));
  return path;
}

// Runs `load`; gi::Error is the expected way to refuse an input.
template <class Load>
void expectSceneOrError(Load&& load) {
  try {
    load();
  } catch (const gi::Error&) {
  }
}

inline std::string_view asText(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace gi::fuzz
