// Strict reading of JSON scene files: every value is read through a JsonObject that knows its
// path ("lights[0].color") and the file, so that each problem is reported as
// "<file>: <path>: <problem>" with ErrorKind::Schema (wrong type, unknown or missing key) or
// InvalidData (a well-typed value out of range).
#pragma once

#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace gi::detail {

// The numbers of the JSON array `value` found at `path` of `file`: Schema error unless it is an
// array whose length is one of `sizes` (any length when `sizes` is empty) holding only numbers,
// InvalidData for a number beyond float range. Elements are named "<path>[i]".
std::vector<float> numberList(const nlohmann::json& value, const std::string& path,
                              const std::string& file, std::initializer_list<size_t> sizes = {});

// A JSON number at `path` as a finite float: Schema error for another type, InvalidData beyond
// float range.
float numberValue(const nlohmann::json& value, const std::string& path, const std::string& file);

class JsonObject {
 public:
  // Throws Schema unless `value` is an object.
  JsonObject(const nlohmann::json& value, std::string path, const std::string& file);

  // Throws Schema for the first key not in `allowed`.
  void allowOnly(std::initializer_list<const char*> allowed) const;
  bool has(const char* key) const { return value_.contains(key); }
  const nlohmann::json& at(const char* key) const { return value_.at(key); }
  // Path of a key below this object ("lights[0]" + "color" -> "lights[0].color").
  std::string pathOf(const std::string& key) const;
  // This object's own path ("" at the top level) and the file, for messages about the whole.
  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }

  // Optional typed values: std::nullopt when absent, Schema error when of the wrong type.
  std::optional<std::string> string(const char* key) const;
  std::optional<bool> boolean(const char* key) const;
  std::optional<float> number(const char* key) const;  // finite, fits a float
  std::optional<int> integer(const char* key) const;
  std::optional<glm::vec3> vec3(const char* key) const;  // [x, y, z]
  // A list of 1..4 numbers; `sizes` names the accepted lengths for the message.
  std::optional<std::vector<float>> numbers(const char* key,
                                            std::initializer_list<size_t> sizes) const;

  // Required variants: Schema error "<path>: missing required key" when absent.
  std::string requireString(const char* key) const;
  glm::vec3 requireVec3(const char* key) const;

  [[noreturn]] void schemaError(const std::string& key, const std::string& problem) const;
  [[noreturn]] void invalid(const std::string& key, const std::string& problem) const;

 private:
  const nlohmann::json& value_;
  std::string path_;
  const std::string& file_;
};

}  // namespace gi::detail
