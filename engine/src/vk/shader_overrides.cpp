#include "gi/vk/shader_overrides.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <mutex>

namespace gi::vk {

namespace {

struct Entry {
  const ShaderRegistration* owner;
  const uint32_t* words;
  size_t count;
  ShaderSource source;
};

struct Table {
  std::mutex mutex;
  std::vector<Entry> entries;
  std::map<std::string, std::vector<uint32_t>> overrides;  // by source path
};

// Never destroyed: modules' registrations may unregister during static destruction.
Table& table() {
  static Table* t = new Table;
  return *t;
}

}  // namespace

ShaderRegistration::ShaderRegistration(const uint32_t* words, size_t count, const char* path,
                                       const char* includeDir) {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  t.entries.push_back({this, words, count, {path, includeDir}});
}

ShaderRegistration::~ShaderRegistration() {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  std::erase_if(t.entries, [&](const Entry& e) { return e.owner == this; });
}

std::vector<ShaderSource> registeredShaderSources() {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  std::map<std::string, ShaderSource> unique;
  for (const Entry& e : t.entries) unique.emplace(e.source.path, e.source);
  std::vector<ShaderSource> out;
  for (auto& [path, source] : unique) out.push_back(source);
  return out;
}

void setShaderOverride(const std::string& path, std::vector<uint32_t> spirv) {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  t.overrides[path] = std::move(spirv);
}

void clearShaderOverride(const std::string& path) {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  t.overrides.erase(path);
}

void clearShaderOverrides() {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  t.overrides.clear();
}

std::vector<uint32_t> resolveShader(const std::vector<uint32_t>& spirv) {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  if (t.overrides.empty()) return spirv;
  // Effects copy their words into a vector: recognise the shader by its content.
  for (const Entry& e : t.entries)
    if (e.count == spirv.size() &&
        std::memcmp(e.words, spirv.data(), spirv.size() * sizeof(uint32_t)) == 0)
      if (auto o = t.overrides.find(e.source.path); o != t.overrides.end()) return o->second;
  return spirv;
}

}  // namespace gi::vk
