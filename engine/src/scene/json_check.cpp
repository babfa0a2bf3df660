#include "json_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gi/errors.h"

namespace gi::detail {

using nlohmann::json;

namespace {

const char* typeName(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

}  // namespace

JsonObject::JsonObject(const json& value, std::string path, const std::string& file)
    : value_(value), path_(std::move(path)), file_(file) {
  if (!value_.is_object())
    throw Error(ErrorKind::Schema, file_,
                (path_.empty() ? std::string("top level") : path_) + ": expected an object, got " +
                    typeName(value_));
}

std::string JsonObject::pathOf(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void JsonObject::schemaError(const std::string& key, const std::string& problem) const {
  throw Error(ErrorKind::Schema, file_, pathOf(key) + ": " + problem);
}

void JsonObject::invalid(const std::string& key, const std::string& problem) const {
  throw Error(ErrorKind::InvalidData, file_, pathOf(key) + ": " + problem);
}

void JsonObject::allowOnly(std::initializer_list<const char*> allowed) const {
  for (const auto& item : value_.items()) {
    bool known =
        std::any_of(allowed.begin(), allowed.end(), [&](const char* k) { return item.key() == k; });
    if (!known) {
      std::string list;
      for (const char* k : allowed) list += (list.empty() ? "" : ", ") + std::string(k);
      schemaError(item.key(), "unknown key (allowed here: " + list + ")");
    }
  }
}

std::optional<std::string> JsonObject::string(const char* key) const {
  if (!has(key)) return std::nullopt;
  const json& v = value_.at(key);
  if (!v.is_string()) schemaError(key, std::string("expected a string, got ") + typeName(v));
  return v.get<std::string>();
}

std::optional<bool> JsonObject::boolean(const char* key) const {
  if (!has(key)) return std::nullopt;
  const json& v = value_.at(key);
  if (!v.is_boolean()) schemaError(key, std::string("expected true or false, got ") + typeName(v));
  return v.get<bool>();
}

namespace {
// A JSON number as a finite float, or nullopt (the caller names the key).
std::optional<float> asFloat(const json& v) {
  if (!v.is_number()) return std::nullopt;
  const double d = v.get<double>();
  if (!std::isfinite(d) || std::abs(d) > std::numeric_limits<float>::max()) return std::nullopt;
  return static_cast<float>(d);
}
}  // namespace

std::optional<float> JsonObject::number(const char* key) const {
  if (!has(key)) return std::nullopt;
  const json& v = value_.at(key);
  if (!v.is_number()) schemaError(key, std::string("expected a number, got ") + typeName(v));
  std::optional<float> f = asFloat(v);
  if (!f) invalid(key, "number out of range");
  return f;
}

std::optional<int> JsonObject::integer(const char* key) const {
  if (!has(key)) return std::nullopt;
  const json& v = value_.at(key);
  if (!v.is_number_integer())
    schemaError(key, std::string("expected an integer, got ") + typeName(v));
  const long long i = v.get<long long>();
  if (i < std::numeric_limits<int>::min() || i > std::numeric_limits<int>::max())
    invalid(key, "integer out of range");
  return static_cast<int>(i);
}

float numberValue(const json& v, const std::string& path, const std::string& file) {
  if (!v.is_number())
    throw Error(ErrorKind::Schema, file, path + ": expected a number, got " + typeName(v));
  std::optional<float> f = asFloat(v);
  if (!f) throw Error(ErrorKind::InvalidData, file, path + ": number out of range");
  return *f;
}

std::vector<float> numberList(const json& v, const std::string& path, const std::string& file,
                              std::initializer_list<size_t> sizes) {
  auto fail = [&](ErrorKind kind, const std::string& where, const std::string& problem) {
    throw Error(kind, file, where + ": " + problem);
  };
  std::string expected;
  for (size_t n : sizes) expected += (expected.empty() ? "" : " or ") + std::to_string(n);
  if (!v.is_array())
    fail(ErrorKind::Schema, path,
         "expected an array of " + (expected.empty() ? std::string() : expected + " ") +
             "numbers, got " + typeName(v));
  if (sizes.size() && std::find(sizes.begin(), sizes.end(), v.size()) == sizes.end())
    fail(ErrorKind::Schema, path,
         "expected an array of " + expected + " numbers, got " + std::to_string(v.size()) +
             " elements");
  std::vector<float> out;
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string where = path + "[" + std::to_string(i) + "]";
    if (!v[i].is_number())
      fail(ErrorKind::Schema, where, std::string("expected a number, got ") + typeName(v[i]));
    std::optional<float> f = asFloat(v[i]);
    if (!f) fail(ErrorKind::InvalidData, where, "number out of range");
    out.push_back(*f);
  }
  return out;
}

std::optional<std::vector<float>> JsonObject::numbers(const char* key,
                                                      std::initializer_list<size_t> sizes) const {
  if (!has(key)) return std::nullopt;
  return numberList(value_.at(key), pathOf(key), file_, sizes);
}

std::optional<glm::vec3> JsonObject::vec3(const char* key) const {
  std::optional<std::vector<float>> v = numbers(key, {3});
  if (!v) return std::nullopt;
  return glm::vec3((*v)[0], (*v)[1], (*v)[2]);
}

std::string JsonObject::requireString(const char* key) const {
  if (!has(key)) schemaError(key, "missing required key");
  return *string(key);
}

glm::vec3 JsonObject::requireVec3(const char* key) const {
  if (!has(key)) schemaError(key, "missing required key");
  return *vec3(key);
}

}  // namespace gi::detail
