// Errors raised while loading or validating input: each names the file and the problem, and
// carries a category so callers (and tests) can tell the kinds of failure apart.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace gi {

enum class ErrorKind {
  FileNotFound,     // path does not exist or cannot be opened
  EmptyFile,        // file exists but has no content
  Parse,            // not valid JSON/glTF/OBJ/PLY syntax
  Schema,           // valid syntax, wrong structure or types (wrong JSON types, unknown keys)
  IndexOutOfRange,  // an index points past the data it refers to
  MissingResource,  // a referenced file (buffer, image, glTF) is missing
  NonFinite,        // NaN/Inf in data that must be finite, and nothing usable remained
  Cycle,            // node hierarchy is not a tree
  InvalidData,      // inconsistent data (accessor counts differ, no geometry, ...)
  Unsupported,      // feature or format we do not handle
  Vulkan,           // Vulkan call failed
  Usage,            // bad command-line argument
  ShaderInterface,  // a shader's bindings or blocks disagree with the C++ that uses them
  Output,           // an output path that cannot be written: not a folder, not a regular file,
                    // no permission, the write failed (a missing file to read is FileNotFound)
};

const char* errorKindName(ErrorKind kind);

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, std::string file, const std::string& problem)
      : std::runtime_error(file.empty() ? problem : file + ": " + problem),
        kind_(kind),
        file_(std::move(file)) {}
  ErrorKind kind() const { return kind_; }
  const std::string& file() const { return file_; }

 private:
  ErrorKind kind_;
  std::string file_;
};

// An error in an effect's code, or raised on its behalf (a check of what it declared, a pass it
// added that failed while recording): `effect()` names it, so an app can turn that effect off
// and go on.
class EffectError : public Error {
 public:
  EffectError(ErrorKind kind, std::string file, const std::string& problem, std::string effect)
      : Error(kind, std::move(file), problem), effect_(std::move(effect)) {}
  const std::string& effect() const { return effect_; }

 private:
  std::string effect_;
};

}  // namespace gi
