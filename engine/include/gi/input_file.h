// Reading input files (scenes, models, material libraries, presets, textures): only regular
// files, of bounded size, so that a FIFO, a device (/dev/zero) or a huge file fails at once with
// a message instead of being read until memory runs out.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace gi {

inline constexpr uint64_t kMaxInputFileBytes = uint64_t(1) << 31;  // 2 GiB

// Throws gi::Error naming `path`: FileNotFound when it does not exist, is a directory ("is a
// directory, not a <what>"), is not a regular file or cannot be opened; Unsupported when it is
// larger than `maxBytes`. Returns the file's size in bytes.
uint64_t checkInputFile(const std::string& path, const std::string& what = "file",
                        uint64_t maxBytes = kMaxInputFileBytes);

// The whole file, after the checks of checkInputFile (an empty file is returned empty).
std::string readInputFile(const std::string& path, const std::string& what = "file",
                          uint64_t maxBytes = kMaxInputFileBytes);

// As readInputFile, but returns false and sets `problem` (without the path) instead of throwing.
bool tryReadInputFile(const std::string& path, std::vector<unsigned char>& bytes,
                      std::string& problem, const std::string& what = "file",
                      uint64_t maxBytes = kMaxInputFileBytes);

// JSON text of the file `path` (scenes, presets, glTF): throws Parse ("invalid JSON: ..." with
// nlohmann's line and column) or InvalidData for a number beyond double range ("number '1e400'
// is out of range ..."), both naming `path`.
nlohmann::json parseJsonText(std::string_view text, const std::string& path,
                             bool allowComments = false);

}  // namespace gi
