// glTF 2.0 loader (.gltf and .glb).
//
// tinygltf reads the container, the buffers (GLB chunk, data URIs, external .bin) and the image
// files. It silently ignores properties of the wrong JSON type, so the JSON is first checked
// here against the parts of the glTF schema that matter to us. Everything tinygltf does not
// check is checked while converting: accessor/bufferView bounds, index values, attribute
// counts, the node graph being a forest. Geometry then goes through processMesh, which drops
// non-finite and degenerate triangles and repairs normals.
//
// tinygltf's implementation is not compiled here: the distribution's libtinygltf (linked
// through TinyGLTF::TinyGLTF) already contains it, built against libstb.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <stb_image.h>
#include <tiny_gltf.h>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "gi/errors.h"
#include "gi/input_file.h"
#include "gi/scene_io.h"

namespace gi {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------------------------------------
// File and container

std::vector<unsigned char> readWholeFile(const std::string& path) {
  // tinygltf takes the size as a 32-bit unsigned (GLB's own limit too).
  const uint64_t size = checkInputFile(path, "glTF file", std::numeric_limits<uint32_t>::max());
  if (size == 0) throw Error(ErrorKind::EmptyFile, path, "file is empty");
  std::vector<unsigned char> bytes;
  std::string problem;
  if (!tryReadInputFile(path, bytes, problem, "glTF file", std::numeric_limits<uint32_t>::max()))
    throw Error(ErrorKind::FileNotFound, path, problem);
  if (bytes.empty()) throw Error(ErrorKind::EmptyFile, path, "file is empty");
  return bytes;
}

// tinygltf's file access for buffers and images: only regular files of bounded size (its own
// reader turns a directory into a size of 2^64-1 and std::bad_alloc, and reads a FIFO forever),
// and no shell-style expansion of the uri.
bool fileExists(const std::string& path, void*) {
  std::error_code ec;
  return fs::exists(path, ec);
}
std::string expandNothing(const std::string& path, void*) {
  return path;
}
bool readChecked(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                 void*) {
  std::string problem;
  if (tryReadInputFile(path, *out, problem, "file")) return true;
  if (err) *err += problem;  // tinygltf adds "File read error : <path> : "
  return false;
}
bool writeNothing(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is not supported\n";
  return false;
}

uint32_t readU32(const unsigned char* p) {  // GLB is little-endian
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

bool hasGlbMagic(const std::vector<unsigned char>& bytes) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

// The JSON chunk of a GLB: 12-byte header (magic, version, length), then chunk 0 (length,
// type "JSON", data). The BIN chunk is left to tinygltf.
std::string_view glbJsonChunk(const std::vector<unsigned char>& bytes, const std::string& path) {
  constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON" read as little-endian u32
  if (bytes.size() < 20)
    throw Error(ErrorKind::Parse, path,
                "truncated binary glTF: " + std::to_string(bytes.size()) +
                    " bytes, but the header and first chunk header need 20");
  const uint32_t version = readU32(&bytes[4]);
  if (version == 1)
    throw Error(ErrorKind::Unsupported, path,
                "glTF 1.0 is not supported (binary glTF version 1; only glTF 2.x is read)");
  if (version != 2)
    throw Error(
        ErrorKind::Unsupported, path,
        "binary glTF version " + std::to_string(version) + " (only version 2 is supported)");
  const uint32_t length = readU32(&bytes[8]);
  if (length > bytes.size())
    throw Error(ErrorKind::Parse, path,
                "truncated binary glTF: header says " + std::to_string(length) +
                    " bytes, file has " + std::to_string(bytes.size()));
  const uint32_t chunkLength = readU32(&bytes[12]);
  if (readU32(&bytes[16]) != kChunkJson)
    throw Error(ErrorKind::Parse, path, "binary glTF: the first chunk is not the JSON chunk");
  if (uint64_t(chunkLength) + 20 > length)
    throw Error(ErrorKind::Parse, path,
                "binary glTF: JSON chunk of " + std::to_string(chunkLength) +
                    " bytes extends past the end of the file");
  return {reinterpret_cast<const char*>(&bytes[20]), chunkLength};
}

// ---------------------------------------------------------------------------------------------
// JSON schema check (the subset of the glTF 2.0 schema this loader and tinygltf read)

enum class JsonKind {
  Uint,  // non-negative integer (index, count, byte offset)
  Number,
  String,
  Bool,
  Object,       // object with the given shape
  ObjectArray,  // array of objects with the given shape
  UintArray,
  NumberArray,  // optionally of an exact length
  StringArray,
  UintMap,       // object whose values are all indices (primitive attributes)
  UintMapArray,  // array of such objects (morph targets)
};

struct Shape;
struct Field {
  const char* name;
  JsonKind kind;
  bool required = false;
  const Shape* shape = nullptr;  // Object, ObjectArray
  size_t length = 0;             // NumberArray: exact length, 0 for any
};
// Known properties of one kind of object. Every object may also have "name" (string),
// "extras" (anything) and "extensions" (an object of objects); `extensions` lists the
// extensions whose contents are checked too. Unknown properties are allowed.
struct Shape {
  std::vector<Field> fields;
  std::vector<Field> extensions;
};

using K = JsonKind;
const Shape kAsset{{{"version", K::String, true},
                    {"minVersion", K::String},
                    {"generator", K::String},
                    {"copyright", K::String}}};
const Shape kScene{{{"nodes", K::UintArray}}};
const Shape kNodeLight{{{"light", K::Uint, true}}};
const Shape kNode{{{"camera", K::Uint},
                   {"children", K::UintArray},
                   {"skin", K::Uint},
                   {"matrix", K::NumberArray, false, nullptr, 16},
                   {"mesh", K::Uint},
                   {"rotation", K::NumberArray, false, nullptr, 4},
                   {"scale", K::NumberArray, false, nullptr, 3},
                   {"translation", K::NumberArray, false, nullptr, 3},
                   {"weights", K::NumberArray}},
                  {{"KHR_lights_punctual", K::Object, false, &kNodeLight}}};
const Shape kPrimitive{{{"attributes", K::UintMap, true},
                        {"indices", K::Uint},
                        {"material", K::Uint},
                        {"mode", K::Uint},
                        {"targets", K::UintMapArray}}};
const Shape kMesh{{{"primitives", K::ObjectArray, true, &kPrimitive}, {"weights", K::NumberArray}}};
const Shape kSparseIndices{
    {{"bufferView", K::Uint, true}, {"byteOffset", K::Uint}, {"componentType", K::Uint, true}}};
const Shape kSparseValues{{{"bufferView", K::Uint, true}, {"byteOffset", K::Uint}}};
const Shape kSparse{{{"count", K::Uint, true},
                     {"indices", K::Object, true, &kSparseIndices},
                     {"values", K::Object, true, &kSparseValues}}};
const Shape kAccessor{{{"bufferView", K::Uint},
                       {"byteOffset", K::Uint},
                       {"componentType", K::Uint, true},
                       {"normalized", K::Bool},
                       {"count", K::Uint, true},
                       {"type", K::String, true},
                       {"max", K::NumberArray},
                       {"min", K::NumberArray},
                       {"sparse", K::Object, false, &kSparse}}};
const Shape kBufferView{{{"buffer", K::Uint, true},
                         {"byteOffset", K::Uint},
                         {"byteLength", K::Uint, true},
                         {"byteStride", K::Uint},
                         {"target", K::Uint}}};
const Shape kBuffer{{{"uri", K::String}, {"byteLength", K::Uint, true}}};
// textureInfo, normalTextureInfo (scale) and occlusionTextureInfo (strength) in one.
const Shape kTextureInfo{{{"index", K::Uint, true},
                          {"texCoord", K::Uint},
                          {"scale", K::Number},
                          {"strength", K::Number}}};
const Shape kPbr{{{"baseColorFactor", K::NumberArray, false, nullptr, 4},
                  {"baseColorTexture", K::Object, false, &kTextureInfo},
                  {"metallicFactor", K::Number},
                  {"roughnessFactor", K::Number},
                  {"metallicRoughnessTexture", K::Object, false, &kTextureInfo}}};
const Shape kEmissiveStrength{{{"emissiveStrength", K::Number}}};
const Shape kMaterial{{{"pbrMetallicRoughness", K::Object, false, &kPbr},
                       {"normalTexture", K::Object, false, &kTextureInfo},
                       {"occlusionTexture", K::Object, false, &kTextureInfo},
                       {"emissiveTexture", K::Object, false, &kTextureInfo},
                       {"emissiveFactor", K::NumberArray, false, nullptr, 3},
                       {"alphaMode", K::String},
                       {"alphaCutoff", K::Number},
                       {"doubleSided", K::Bool}},
                      {{"KHR_materials_emissive_strength", K::Object, false, &kEmissiveStrength}}};
const Shape kTexture{{{"sampler", K::Uint}, {"source", K::Uint}}};
const Shape kImage{{{"uri", K::String}, {"mimeType", K::String}, {"bufferView", K::Uint}}};
const Shape kSampler{
    {{"magFilter", K::Uint}, {"minFilter", K::Uint}, {"wrapS", K::Uint}, {"wrapT", K::Uint}}};
const Shape kPerspective{{{"aspectRatio", K::Number},
                          {"yfov", K::Number, true},
                          {"zfar", K::Number},
                          {"znear", K::Number, true}}};
const Shape kOrthographic{{{"xmag", K::Number, true},
                           {"ymag", K::Number, true},
                           {"zfar", K::Number, true},
                           {"znear", K::Number, true}}};
const Shape kCamera{{{"type", K::String, true},
                     {"perspective", K::Object, false, &kPerspective},
                     {"orthographic", K::Object, false, &kOrthographic}}};
const Shape kSkin{
    {{"inverseBindMatrices", K::Uint}, {"skeleton", K::Uint}, {"joints", K::UintArray, true}}};
const Shape kChannelTarget{{{"node", K::Uint}, {"path", K::String, true}}};
const Shape kChannel{{{"sampler", K::Uint, true}, {"target", K::Object, true, &kChannelTarget}}};
const Shape kAnimationSampler{
    {{"input", K::Uint, true}, {"interpolation", K::String}, {"output", K::Uint, true}}};
const Shape kAnimation{{{"channels", K::ObjectArray, true, &kChannel},
                        {"samplers", K::ObjectArray, true, &kAnimationSampler}}};
const Shape kSpot{{{"innerConeAngle", K::Number}, {"outerConeAngle", K::Number}}};
const Shape kLight{{{"type", K::String, true},
                    {"color", K::NumberArray, false, nullptr, 3},
                    {"intensity", K::Number},
                    {"range", K::Number},
                    {"spot", K::Object, false, &kSpot}}};
const Shape kLightsPunctual{{{"lights", K::ObjectArray, false, &kLight}}};
const Shape kRoot{{{"asset", K::Object, true, &kAsset},
                   {"scene", K::Uint},
                   {"scenes", K::ObjectArray, false, &kScene},
                   {"nodes", K::ObjectArray, false, &kNode},
                   {"meshes", K::ObjectArray, false, &kMesh},
                   {"accessors", K::ObjectArray, false, &kAccessor},
                   {"bufferViews", K::ObjectArray, false, &kBufferView},
                   {"buffers", K::ObjectArray, false, &kBuffer},
                   {"materials", K::ObjectArray, false, &kMaterial},
                   {"textures", K::ObjectArray, false, &kTexture},
                   {"images", K::ObjectArray, false, &kImage},
                   {"samplers", K::ObjectArray, false, &kSampler},
                   {"cameras", K::ObjectArray, false, &kCamera},
                   {"skins", K::ObjectArray, false, &kSkin},
                   {"animations", K::ObjectArray, false, &kAnimation},
                   {"extensionsUsed", K::StringArray},
                   {"extensionsRequired", K::StringArray}},
                  {{"KHR_lights_punctual", K::Object, false, &kLightsPunctual}}};

// Walks a parsed document against the shapes above; the first mismatch throws Schema with the
// JSON path of the offending value ("meshes[0].primitives: expected an array, found object").
class SchemaCheck {
 public:
  explicit SchemaCheck(const std::string& file) : file_(file) {}

  void object(const json& j, const Shape& shape, const std::string& where) const {
    if (!j.is_object()) mismatch(where, "an object", j);
    for (const Field& f : shape.fields) {
      auto it = j.find(f.name);
      if (it == j.end()) {
        if (f.required)
          throw Error(ErrorKind::Schema, file_,
                      join(where, f.name) + ": required property is missing");
        continue;
      }
      value(*it, f, join(where, f.name));
    }
    if (auto it = j.find("name"); it != j.end() && !it->is_string())
      mismatch(join(where, "name"), "a string", *it);
    if (auto it = j.find("extensions"); it != j.end()) {
      const std::string at = join(where, "extensions");
      if (!it->is_object()) mismatch(at, "an object", *it);
      for (const auto& [key, extension] : it->items()) {
        if (!extension.is_object()) mismatch(join(at, key), "an object", extension);
        for (const Field& f : shape.extensions)
          if (key == f.name) value(extension, f, join(at, key));
      }
    }
  }

 private:
  static std::string join(const std::string& where, const std::string& key) {
    return where.empty() ? key : where + "." + key;
  }
  static std::string element(const std::string& where, size_t i) {
    return where + "[" + std::to_string(i) + "]";
  }
  // glTF indices are JSON integers (tinygltf rejects 1.0 as well); they must also fit an int.
  static bool isUint(const json& v) {
    return v.is_number_unsigned() &&
           v.get<uint64_t>() <= uint64_t(std::numeric_limits<int32_t>::max());
  }

  [[noreturn]] void mismatch(const std::string& where, const std::string& expected,
                             const json& found) const {
    std::string text = found.dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    throw Error(ErrorKind::Schema, file_,
                (where.empty() ? std::string("document") : where) + ": expected " + expected +
                    ", found " + found.type_name() + " " + text);
  }

  void array(const json& v, const std::string& where, const char* expected) const {
    if (!v.is_array()) mismatch(where, expected, v);
  }

  void uintMap(const json& v, const std::string& where) const {
    if (!v.is_object()) mismatch(where, "an object of accessor indices", v);
    for (const auto& [key, index] : v.items())
      if (!isUint(index)) mismatch(join(where, key), "a non-negative integer", index);
  }

  void value(const json& v, const Field& f, const std::string& where) const {
    switch (f.kind) {
      case K::Uint:
        if (!isUint(v)) mismatch(where, "a non-negative integer", v);
        break;
      case K::Number:
        if (!v.is_number()) mismatch(where, "a number", v);
        break;
      case K::String:
        if (!v.is_string()) mismatch(where, "a string", v);
        break;
      case K::Bool:
        if (!v.is_boolean()) mismatch(where, "a boolean", v);
        break;
      case K::Object:
        object(v, *f.shape, where);
        break;
      case K::ObjectArray:
        array(v, where, "an array of objects");
        for (size_t i = 0; i < v.size(); ++i) object(v[i], *f.shape, element(where, i));
        break;
      case K::UintArray:
        array(v, where, "an array of non-negative integers");
        for (size_t i = 0; i < v.size(); ++i)
          if (!isUint(v[i])) mismatch(element(where, i), "a non-negative integer", v[i]);
        break;
      case K::NumberArray: {
        const std::string expected = f.length
                                         ? "an array of " + std::to_string(f.length) + " numbers"
                                         : "an array of numbers";
        array(v, where, expected.c_str());
        if (f.length && v.size() != f.length) mismatch(where, expected, v);
        for (size_t i = 0; i < v.size(); ++i)
          if (!v[i].is_number()) mismatch(element(where, i), "a number", v[i]);
        break;
      }
      case K::StringArray:
        array(v, where, "an array of strings");
        for (size_t i = 0; i < v.size(); ++i)
          if (!v[i].is_string()) mismatch(element(where, i), "a string", v[i]);
        break;
      case K::UintMap:
        uintMap(v, where);
        break;
      case K::UintMapArray:
        array(v, where, "an array of objects");
        for (size_t i = 0; i < v.size(); ++i) uintMap(v[i], element(where, i));
        break;
    }
  }

  const std::string& file_;
};

// ---------------------------------------------------------------------------------------------
// tinygltf glue

// Image callback: keep the encoded bytes. Only images a material uses get decoded (to RGBA8,
// in GltfLoader::textureFor), so an unused or exotic image costs nothing and cannot fail.
bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  return true;
}

// tinygltf reports failures only as text. What is left after our own checks is about
// resources (missing or short buffers, bad data URIs) and the GLB container; sort by wording.
ErrorKind classifyTinygltfError(const std::string& err) {
  auto has = [&](const char* s) { return err.find(s) != std::string::npos; };
  if (has("File not found") || has("File open error") || has("File read error"))
    return ErrorKind::MissingResource;
  if (has("out of bounds") || has("not found in the scene") || has("invalid bufferView"))
    return ErrorKind::IndexOutOfRange;
  if (has("size mismatch") || has("`byteLength'") || has("Failed to decode") ||
      has("File is empty") || has("in `Buffer'"))
    return ErrorKind::InvalidData;
  if (has("magic") || has("Chunk") || has("glTF Binary") || has("glTF binary") || has("JSON"))
    return ErrorKind::Parse;
  return ErrorKind::Schema;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

const char* typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
  }
  return "unknown type";
}

const char* componentTypeName(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
  }
  return "unknown component type";
}

// A bounds-checked run of accessor elements inside a buffer.
struct Elements {
  const unsigned char* data = nullptr;
  size_t stride = 0;
  int componentType = 0;
  size_t componentSize = 0;

  // One component, as stored (not normalised).
  double get(size_t element, size_t component) const {
    const unsigned char* p = data + element * stride + component * componentSize;
    auto load = [p](auto v) {
      std::memcpy(&v, p, sizeof(v));  // glTF data need not be aligned for the host
      return static_cast<double>(v);
    };
    switch (componentType) {
      case TINYGLTF_COMPONENT_TYPE_BYTE:
        return load(int8_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return load(uint8_t{});
      case TINYGLTF_COMPONENT_TYPE_SHORT:
        return load(int16_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return load(uint16_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return load(uint32_t{});
      default:
        return load(float{});  // FLOAT: the component types were checked before
    }
  }
};

// Normalised integer to float, as the glTF spec defines it.
double normalise(double v, int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return std::max(v / 127.0, -1.0);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return v / 255.0;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return std::max(v / 32767.0, -1.0);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return v / 65535.0;
    default:
      return v;
  }
}

bool finite(const glm::mat4& m) {
  const float* p = glm::value_ptr(m);
  return std::all_of(p, p + 16, [](float f) { return std::isfinite(f); });
}

// ---------------------------------------------------------------------------------------------
// Conversion

class GltfLoader {
 public:
  explicit GltfLoader(const std::string& path) : path_(path) {}

  Scene load() {
    parse();
    scene_.sourcePath = path_;
    convertCameras();
    convertLights();
    imageTexture_.assign(model_.images.size(), -1);
    meshCache_.assign(model_.meshes.size(), std::nullopt);
    convertMaterials();
    checkHierarchy();
    std::vector<int> roots = sceneRoots();
    sceneNode_.assign(model_.nodes.size(), -1);
    for (int root : roots) addSubtree(root);
    if (roots.empty()) {
      // No scene or no nodes at all: show every mesh once, untransformed.
      for (size_t m = 0; m < model_.meshes.size(); ++m) {
        int node = scene_.addNode("mesh " + std::to_string(m), glm::mat4(1.0f));
        scene_.nodes[node].meshes = meshesOf(static_cast<int>(m), "scene root");
      }
    }
    if (scene_.meshes.empty()) {
      if (droppedNonFinite_ > 0)
        fail(ErrorKind::NonFinite, "no geometry left after dropping " +
                                       std::to_string(droppedNonFinite_) +
                                       " triangles with non-finite (NaN/Inf) vertex positions");
      fail(ErrorKind::InvalidData, "no geometry: the scene has no triangles to render (" +
                                       std::to_string(model_.meshes.size()) + " meshes, " +
                                       std::to_string(model_.nodes.size()) + " nodes in the file)");
    }
    convertSkins();
    convertAnimations();
    scene_.updateWorldTransforms();
    return std::move(scene_);
  }

 private:
  [[noreturn]] void fail(ErrorKind kind, const std::string& problem) const {
    throw Error(kind, path_, problem);
  }
  // A value out of its range: "<file>: <where>: <problem>", as the JSON scene loader says it.
  [[noreturn]] void invalid(const std::string& where, const std::string& problem) const {
    fail(ErrorKind::InvalidData, where + ": " + problem);
  }
  static std::string num(double v) {
    std::ostringstream s;
    s << v;  // as written: 0.5, 1e+30, not 0.500000
    return s.str();
  }
  void warn(const std::string& message) { scene_.warnings.push_back(path_ + ": " + message); }

  // File -> checked JSON -> tinygltf model.
  void parse() {
    const std::vector<unsigned char> bytes = readWholeFile(path_);
    const bool binary = hasGlbMagic(bytes);
    if (!binary && fs::path(path_).extension() == ".glb")
      fail(ErrorKind::Parse, "not a binary glTF file (no 'glTF' magic at the start)");
    const std::string_view text =
        binary ? glbJsonChunk(bytes, path_)
               : std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());

    const json doc = parseJsonText(text, path_);
    checkVersion(doc);
    SchemaCheck(path_).object(doc, kRoot, "");
    checkRequiredExtensions(doc);

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&keepEncodedImage, nullptr);
    loader.SetFsCallbacks({&fileExists, &expandNothing, &readChecked, &writeNothing, nullptr});
    std::string err, warnings;
    std::string baseDir = fs::path(path_).parent_path().string();
    if (baseDir.empty()) baseDir = ".";
    const bool ok =
        binary ? loader.LoadBinaryFromMemory(&model_, &err, &warnings, bytes.data(),
                                             static_cast<unsigned int>(bytes.size()), baseDir)
               : loader.LoadASCIIFromString(&model_, &err, &warnings, text.data(),
                                            static_cast<unsigned int>(text.size()), baseDir);
    if (!ok) {
      const ErrorKind kind = classifyTinygltfError(err);
      fail(kind, "tinygltf: " + trimmed(err) +
                     (kind == ErrorKind::MissingResource ? " (relative to " + baseDir + ")" : ""));
    }
    if (!trimmed(warnings).empty()) warn("tinygltf: " + trimmed(warnings));
  }

  // Before the schema check: a glTF 1.0 file fails it in ways that do not say what is wrong
  // (its "scene" is a string, its meshes an object keyed by id).
  void checkVersion(const json& doc) {
    if (!doc.is_object()) return;  // the schema check names it
    const auto asset = doc.find("asset");
    const bool hasVersion = asset != doc.end() && asset->is_object() &&
                            asset->contains("version") && (*asset)["version"].is_string();
    const std::string version = hasVersion ? (*asset)["version"].get<std::string>() : "";
    const bool v1Layout = (doc.contains("scene") && doc["scene"].is_string()) ||
                          (doc.contains("meshes") && doc["meshes"].is_object()) ||
                          (doc.contains("nodes") && doc["nodes"].is_object());
    if (version.rfind("1.", 0) == 0 || (!hasVersion && v1Layout))
      fail(ErrorKind::Unsupported, "glTF 1.0 is not supported (only glTF 2.x is read)");
    if (hasVersion && version.rfind("2.", 0) != 0)
      fail(ErrorKind::Unsupported, "glTF version " + version + " (only 2.x is supported)");
  }

  // A required extension changes what the file means; showing it without would be wrong.
  void checkRequiredExtensions(const json& doc) {
    static const char* const kSupported[] = {"KHR_lights_punctual",
                                             "KHR_materials_emissive_strength"};
    auto it = doc.find("extensionsRequired");
    if (it == doc.end()) return;
    for (const json& name : *it) {
      const std::string ext = name.get<std::string>();
      if (std::find(std::begin(kSupported), std::end(kSupported), ext) == std::end(kSupported))
        fail(ErrorKind::Unsupported, "requires extension " + ext + ", which is not supported");
    }
  }

  void convertCameras() {
    for (size_t i = 0; i < model_.cameras.size(); ++i) {
      const tinygltf::Camera& gc = model_.cameras[i];
      Camera cam;
      cam.name = gc.name.empty() ? "camera " + std::to_string(i) : gc.name;
      const std::string where = "cameras[" + std::to_string(i) + "]";
      if (gc.type == "perspective") {
        // The same rules as a JSON scene's camera (yfov in (0, 180) degrees, 0 < near < far).
        const tinygltf::PerspectiveCamera& p = gc.perspective;
        if (!(p.yfov > 0.0 && p.yfov < glm::pi<double>()))
          invalid(where + ".perspective.yfov", "must be in (0, pi) radians, got " + num(p.yfov));
        if (!(p.znear > 0.0))
          invalid(where + ".perspective.znear", "must be positive, got " + num(p.znear));
        if (p.zfar != 0.0 && !(p.zfar > p.znear))
          invalid(where + ".perspective.zfar",
                  "must be greater than znear (" + num(p.znear) + "), got " + num(p.zfar));
        if (p.aspectRatio < 0.0)
          invalid(where + ".perspective.aspectRatio",
                  "must be positive, got " + num(p.aspectRatio));
        cam.yfov = static_cast<float>(gc.perspective.yfov);
        cam.aspect = static_cast<float>(gc.perspective.aspectRatio);  // 0 when absent
        cam.znear = static_cast<float>(gc.perspective.znear);
        // zfar absent means an infinite projection; keep a finite far plane well beyond near.
        cam.zfar = gc.perspective.zfar > 0.0 ? static_cast<float>(gc.perspective.zfar)
                                             : std::max(cam.zfar, cam.znear * 1e4f);
      } else if (gc.type == "orthographic") {
        const tinygltf::OrthographicCamera& o = gc.orthographic;
        if (!(o.znear >= 0.0))
          invalid(where + ".orthographic.znear", "must not be negative, got " + num(o.znear));
        if (!(o.zfar > o.znear))
          invalid(where + ".orthographic.zfar",
                  "must be greater than znear (" + num(o.znear) + "), got " + num(o.zfar));
        cam.znear = static_cast<float>(gc.orthographic.znear);
        cam.zfar = static_cast<float>(gc.orthographic.zfar);
        warn(cam.name +
             ": orthographic cameras are not supported; using a perspective camera "
             "with the default field of view");
      } else {
        fail(ErrorKind::Schema, "camera " + std::to_string(i) + " has unknown type '" + gc.type +
                                    "' (expected perspective or orthographic)");
      }
      scene_.cameras.push_back(cam);
    }
  }

  void convertLights() {
    for (size_t i = 0; i < model_.lights.size(); ++i) {
      const tinygltf::Light& gl = model_.lights[i];
      Light light;
      light.name = gl.name.empty() ? "light " + std::to_string(i) : gl.name;
      if (gl.type == "directional") {
        light.type = LightType::Directional;
      } else if (gl.type == "point") {
        light.type = LightType::Point;
      } else if (gl.type == "spot") {
        light.type = LightType::Spot;
        light.innerConeAngle = static_cast<float>(gl.spot.innerConeAngle);
        light.outerConeAngle = static_cast<float>(gl.spot.outerConeAngle);
      } else {
        fail(ErrorKind::Schema, "KHR_lights_punctual light " + std::to_string(i) +
                                    " has unknown type '" + gl.type + "'");
      }
      // The same rules as a JSON scene's light.
      const std::string where = "KHR_lights_punctual.lights[" + std::to_string(i) + "]";
      if (light.type == LightType::Spot) {
        const double inner = gl.spot.innerConeAngle, outer = gl.spot.outerConeAngle;
        if (!(outer > 0.0 && outer <= glm::half_pi<double>()))
          invalid(where + ".spot.outerConeAngle",
                  "must be in (0, pi/2] radians, got " + num(outer));
        if (!(inner >= 0.0 && inner <= outer))
          invalid(where + ".spot.innerConeAngle",
                  "must be in [0, outerConeAngle] (" + num(outer) + "), got " + num(inner));
      }
      if (gl.color.size() == 3) {
        if (gl.color[0] < 0 || gl.color[1] < 0 || gl.color[2] < 0)
          invalid(where + ".color", "colour components must not be negative");
        light.color = glm::vec3(float(gl.color[0]), float(gl.color[1]), float(gl.color[2]));
      }
      if (!(gl.intensity >= 0.0))
        invalid(where + ".intensity", "must not be negative, got " + num(gl.intensity));
      if (!(gl.range >= 0.0))
        invalid(where + ".range", "must not be negative, got " + num(gl.range));
      light.intensity = static_cast<float>(gl.intensity);
      light.range = static_cast<float>(gl.range);
      scene_.lights.push_back(light);
    }
  }

  void convertMaterials() {
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      const tinygltf::Material& gm = model_.materials[i];
      const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
      const std::string what = "material " + std::to_string(i);
      Material mat;
      mat.name = gm.name.empty() ? what : gm.name;
      const std::vector<double>& c = pbr.baseColorFactor;  // tinygltf fills the default
      const std::string where = "materials[" + std::to_string(i) + "]";
      if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[3] < 0)
        invalid(where + ".pbrMetallicRoughness.baseColorFactor",
                "colour components must not be negative");
      mat.baseColor = glm::vec4(float(c[0]), float(c[1]), float(c[2]), float(c[3]));
      // The spec limits both factors to [0, 1].
      mat.metallic = std::clamp(static_cast<float>(pbr.metallicFactor), 0.0f, 1.0f);
      mat.roughness = std::clamp(static_cast<float>(pbr.roughnessFactor), 0.0f, 1.0f);
      if (pbr.baseColorTexture.index >= 0) {
        mat.baseColorTexture = textureFor(pbr.baseColorTexture.index, what);
        if (pbr.baseColorTexture.texCoord != 0)
          warn(what + ": base colour texture uses TEXCOORD_" +
               std::to_string(pbr.baseColorTexture.texCoord) + "; only TEXCOORD_0 is loaded");
      }
      const std::vector<double>& e = gm.emissiveFactor;
      float strength = 1.0f;
      if (auto ext = gm.extensions.find("KHR_materials_emissive_strength");
          ext != gm.extensions.end() && ext->second.Has("emissiveStrength"))
        strength = static_cast<float>(ext->second.Get("emissiveStrength").GetNumberAsDouble());
      // Negative emission would add negative radiance (a JSON scene's "emission" is refused too).
      if (e[0] < 0 || e[1] < 0 || e[2] < 0)
        invalid(where + ".emissiveFactor", "colour components must not be negative");
      if (!(strength >= 0.0f))
        invalid(where + ".extensions.KHR_materials_emissive_strength.emissiveStrength",
                "must not be negative, got " + num(double(strength)));
      mat.emission = glm::vec3(float(e[0]), float(e[1]), float(e[2])) * strength;
      mat.doubleSided = gm.doubleSided;
      scene_.materials.push_back(mat);
    }
  }

  // Scene texture for a glTF texture, decoding its image to RGBA8 the first time; -1 when the
  // texture has no image we can read.
  int textureFor(int textureIndex, const std::string& what) {
    if (size_t(textureIndex) >= model_.textures.size())
      fail(ErrorKind::IndexOutOfRange, what + ": texture " + std::to_string(textureIndex) +
                                           " does not exist (file has " +
                                           std::to_string(model_.textures.size()) + " textures)");
    const int source = model_.textures[textureIndex].source;
    if (source < 0) {  // e.g. only a KHR_texture_basisu / EXT_texture_webp source
      warn(what + ": texture " + std::to_string(textureIndex) +
           " has no PNG/JPEG image source; drawn untextured");
      return -1;
    }
    if (size_t(source) >= model_.images.size())
      fail(ErrorKind::IndexOutOfRange, what + ": texture " + std::to_string(textureIndex) +
                                           " uses image " + std::to_string(source) +
                                           ", which does not exist (file has " +
                                           std::to_string(model_.images.size()) + " images)");
    if (imageTexture_[source] >= 0) return imageTexture_[source];

    const tinygltf::Image& image = model_.images[source];
    const bool external = !image.uri.empty() && !tinygltf::IsDataURI(image.uri);
    const std::string label =
        "image " + std::to_string(source) + (external ? " ('" + image.uri + "')" : std::string());
    if (image.image.empty()) {
      // tinygltf only warns when an image file is missing, leaving the image empty.
      if (external) {
        // Say why: a directory, a device or a file too large is refused by readChecked.
        const fs::path file = fs::path(path_).parent_path() / image.uri;
        std::vector<unsigned char> probe;
        std::string problem;
        std::error_code ec;
        if (fs::exists(file, ec) && !tryReadInputFile(file.string(), probe, problem, "file"))
          fail(ErrorKind::MissingResource,
               what + ": " + label + ": " + file.string() + " " + problem);
        fail(ErrorKind::MissingResource,
             what + ": " + label + " not found (looked next to the glTF file)");
      }
      fail(ErrorKind::InvalidData, what + ": " + label + " has no data");
    }
    if (image.image.size() > size_t(std::numeric_limits<int>::max()))
      fail(ErrorKind::Unsupported, what + ": " + label + " is larger than 2 GiB");
    int width = 0, height = 0, channels = 0;
    stbi_uc* pixels = stbi_load_from_memory(image.image.data(), int(image.image.size()), &width,
                                            &height, &channels, 4);
    if (!pixels)
      fail(ErrorKind::InvalidData,
           what + ": " + label + " cannot be decoded: " +
               // stb may fail without a reason (null: found by fuzzing)
               (stbi_failure_reason() ? stbi_failure_reason() : "unknown image error"));
    Texture tex;
    tex.name = !image.name.empty() ? image.name : external ? image.uri : label;
    tex.width = width;
    tex.height = height;
    tex.rgba8.assign(pixels, pixels + size_t(width) * size_t(height) * 4);
    stbi_image_free(pixels);
    scene_.textures.push_back(std::move(tex));
    imageTexture_[source] = static_cast<int>(scene_.textures.size()) - 1;
    return imageTexture_[source];
  }

  uint32_t materialFor(int materialIndex, const std::string& what) {
    if (materialIndex < 0) {
      if (defaultMaterial_ < 0) {
        Material mat;
        mat.name = "default";
        scene_.materials.push_back(mat);
        defaultMaterial_ = static_cast<int>(scene_.materials.size()) - 1;
      }
      return static_cast<uint32_t>(defaultMaterial_);
    }
    if (size_t(materialIndex) >= model_.materials.size())
      fail(ErrorKind::IndexOutOfRange, what + ": material " + std::to_string(materialIndex) +
                                           " does not exist (file has " +
                                           std::to_string(model_.materials.size()) + " materials)");
    return static_cast<uint32_t>(materialIndex);  // materials were converted in file order
  }

  // Parent of every node from the children lists; rejects anything that is not a forest.
  void checkHierarchy() {
    const size_t count = model_.nodes.size();
    parent_.assign(count, -1);
    for (size_t n = 0; n < count; ++n) {
      for (int child : model_.nodes[n].children) {
        if (size_t(child) >= count)
          fail(ErrorKind::IndexOutOfRange,
               "node " + std::to_string(n) + " has child " + std::to_string(child) +
                   ", which does not exist (file has " + std::to_string(count) + " nodes)");
        if (size_t(child) == n)
          fail(ErrorKind::Cycle, "node " + std::to_string(n) + " lists itself as its child");
        if (parent_[child] >= 0)
          fail(ErrorKind::Cycle, "node " + std::to_string(child) + " is a child of both node " +
                                     std::to_string(parent_[child]) + " and node " +
                                     std::to_string(n) + "; the hierarchy must be a tree");
        parent_[child] = static_cast<int>(n);
      }
    }
    // With one parent each, the only way left to fail is a loop of ancestors. Walk up from
    // every node, remembering nodes already known to lead to a root (linear time overall).
    enum : char { Unvisited, OnPath, ReachesRoot };
    std::vector<char> state(count, Unvisited);
    std::vector<int> path;
    for (size_t n = 0; n < count; ++n) {
      path.clear();
      int m = static_cast<int>(n);
      while (m >= 0 && state[m] == Unvisited) {
        state[m] = OnPath;
        path.push_back(m);
        m = parent_[m];
      }
      if (m >= 0 && state[m] == OnPath) {
        std::string loop = std::to_string(m);
        for (int p = parent_[m]; p != m; p = parent_[p]) loop += " -> " + std::to_string(p);
        fail(ErrorKind::Cycle, "node " + std::to_string(m) + " is its own ancestor (parents: " +
                                   loop + " -> " + std::to_string(m) + ")");
      }
      for (int p : path) state[p] = ReachesRoot;
    }
  }

  // Root nodes to show: the default scene, else scene 0, else every parentless node.
  std::vector<int> sceneRoots() const {
    int sceneIndex = model_.defaultScene;
    if (sceneIndex >= 0 && size_t(sceneIndex) >= model_.scenes.size())
      fail(ErrorKind::IndexOutOfRange, "default scene " + std::to_string(sceneIndex) +
                                           " does not exist (file has " +
                                           std::to_string(model_.scenes.size()) + " scenes)");
    std::vector<int> roots;
    if (sceneIndex < 0 && model_.scenes.empty()) {
      for (size_t n = 0; n < model_.nodes.size(); ++n)
        if (parent_[n] < 0) roots.push_back(static_cast<int>(n));
      return roots;
    }
    sceneIndex = std::max(sceneIndex, 0);
    const std::string what = "scene " + std::to_string(sceneIndex);
    std::vector<char> listed(model_.nodes.size(), 0);
    for (int node : model_.scenes[sceneIndex].nodes) {
      if (size_t(node) >= model_.nodes.size())
        fail(ErrorKind::IndexOutOfRange, what + " lists node " + std::to_string(node) +
                                             ", which does not exist (file has " +
                                             std::to_string(model_.nodes.size()) + " nodes)");
      if (parent_[node] >= 0)
        fail(ErrorKind::Cycle, what + " lists node " + std::to_string(node) +
                                   " as a root, but it is a child of node " +
                                   std::to_string(parent_[node]));
      if (listed[node])
        fail(ErrorKind::Cycle, what + " lists node " + std::to_string(node) + " twice");
      listed[node] = 1;
      roots.push_back(node);
    }
    return roots;
  }

  glm::mat4 localTransform(const tinygltf::Node& node, const std::string& what) {
    glm::mat4 m(1.0f);
    if (node.matrix.size() == 16) {  // column-major in glTF and glm alike
      float* dst = glm::value_ptr(m);
      for (size_t i = 0; i < 16; ++i) dst[i] = static_cast<float>(node.matrix[i]);
    } else {
      if (node.translation.size() == 3)
        m = glm::translate(m, glm::vec3(float(node.translation[0]), float(node.translation[1]),
                                        float(node.translation[2])));
      if (node.rotation.size() == 4) {  // glTF stores x, y, z, w; glm::quat takes w first
        glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                    float(node.rotation[2]));
        const float len = glm::length(q);
        if (std::isfinite(len) && len > 1e-12f) {
          m *= glm::mat4_cast(q / len);
        } else {
          warn(what + ": zero rotation quaternion; using no rotation");
        }
      }
      if (node.scale.size() == 3)
        m = glm::scale(m,
                       glm::vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2])));
    }
    if (!finite(m)) fail(ErrorKind::NonFinite, what + ": transform is not finite");
    return m;
  }

  // Copies a glTF node and its subtree into the scene, depth first with children in file
  // order. Iterative: hierarchies can be deeper than the stack is comfortable with.
  void addSubtree(int root) {
    std::vector<std::pair<int, int>> stack{{root, -1}};  // (glTF node, parent in scene_)
    while (!stack.empty()) {
      const auto [index, parent] = stack.back();
      stack.pop_back();
      const tinygltf::Node& gn = model_.nodes[index];
      const std::string what = "node " + std::to_string(index);
      const int node =
          scene_.addNode(gn.name.empty() ? what : gn.name, localTransform(gn, what), parent);
      sceneNode_[index] = node;
      setTRS(scene_.nodes[node], gn);
      if (gn.mesh >= 0) {
        scene_.nodes[node].meshes = meshesOf(gn.mesh, what);
        // Morph weights: the node's, else the mesh's defaults, else zeros.
        size_t targets = 0;
        for (int m : scene_.nodes[node].meshes)
          targets = std::max(targets, scene_.meshes[m].morphTargets.size());
        std::vector<float> weights(targets, 0.0f);
        const std::vector<double>& src =
            !gn.weights.empty() ? gn.weights : model_.meshes[gn.mesh].weights;
        for (size_t i = 0; i < targets && i < src.size(); ++i) weights[i] = float(src[i]);
        scene_.nodes[node].morphWeights = std::move(weights);
      }
      if (gn.skin >= 0) {
        if (size_t(gn.skin) >= model_.skins.size())
          fail(ErrorKind::IndexOutOfRange, what + ": skin " + std::to_string(gn.skin) +
                                               " does not exist (file has " +
                                               std::to_string(model_.skins.size()) + " skins)");
        scene_.nodes[node].skin = gn.skin;  // glTF skins become scene skins in file order
        if (gn.mesh < 0) warn(what + ": has a skin but no mesh; the skin is unused");
      }
      if (gn.camera >= 0) {
        if (size_t(gn.camera) >= scene_.cameras.size())
          fail(ErrorKind::IndexOutOfRange, what + ": camera " + std::to_string(gn.camera) +
                                               " does not exist (file has " +
                                               std::to_string(scene_.cameras.size()) + " cameras)");
        scene_.nodes[node].camera = gn.camera;
        if (scene_.activeCameraNode < 0) scene_.activeCameraNode = node;
      }
      if (auto ext = gn.extensions.find("KHR_lights_punctual"); ext != gn.extensions.end()) {
        const int light = ext->second.Get("light").GetNumberAsInt();
        if (size_t(light) >= scene_.lights.size())
          fail(ErrorKind::IndexOutOfRange,
               what + ": light " + std::to_string(light) + " does not exist (file has " +
                   std::to_string(scene_.lights.size()) + " KHR_lights_punctual lights)");
        scene_.nodes[node].light = light;
      }
      for (auto c = gn.children.rbegin(); c != gn.children.rend(); ++c)
        stack.emplace_back(*c, node);
    }
  }

  // Translation/rotation/scale of a node as the file gives them (matrix nodes keep hasTRS off:
  // glTF does not allow animating them).
  void setTRS(Node& node, const tinygltf::Node& gn) {
    if (gn.matrix.size() == 16) return;
    node.hasTRS = true;
    if (gn.translation.size() == 3)
      node.translation =
          glm::vec3(float(gn.translation[0]), float(gn.translation[1]), float(gn.translation[2]));
    if (gn.rotation.size() == 4) {
      glm::quat q(float(gn.rotation[3]), float(gn.rotation[0]), float(gn.rotation[1]),
                  float(gn.rotation[2]));
      const float len = glm::length(q);
      node.rotation = std::isfinite(len) && len > 1e-12f ? q / len : glm::quat(1, 0, 0, 0);
    }
    if (gn.scale.size() == 3)
      node.scale = glm::vec3(float(gn.scale[0]), float(gn.scale[1]), float(gn.scale[2]));
  }

  // Skins in file order: joints mapped to scene nodes, inverse bind matrices checked; every
  // skinned mesh's joint indices must fall inside the skin that draws it.
  void convertSkins() {
    for (size_t i = 0; i < model_.skins.size(); ++i) {
      const tinygltf::Skin& gs = model_.skins[i];
      const std::string what = "skin " + std::to_string(i);
      Skin skin;
      skin.name = gs.name.empty() ? what : gs.name;
      for (int joint : gs.joints) {
        if (joint < 0 || size_t(joint) >= model_.nodes.size())
          fail(ErrorKind::IndexOutOfRange, what + ": joint node " + std::to_string(joint) +
                                               " does not exist (file has " +
                                               std::to_string(model_.nodes.size()) + " nodes)");
        if (sceneNode_[joint] < 0)
          warn(what + ": joint node " + std::to_string(joint) +
               " is not part of the scene; it stays at its bind pose");
        skin.joints.push_back(sceneNode_[joint]);
      }
      skin.inverseBindMatrices.assign(skin.joints.size(), glm::mat4(1.0f));
      if (gs.inverseBindMatrices >= 0) {
        const std::string label = what + " inverseBindMatrices";
        requireFormat(gs.inverseBindMatrices, TINYGLTF_TYPE_MAT4, {TINYGLTF_COMPONENT_TYPE_FLOAT},
                      false, label);
        const tinygltf::Accessor& a = accessor(gs.inverseBindMatrices, label);
        if (a.count < skin.joints.size())
          fail(ErrorKind::InvalidData, label + ": accessor " +
                                           std::to_string(gs.inverseBindMatrices) + " has " +
                                           std::to_string(a.count) + " matrices for " +
                                           std::to_string(skin.joints.size()) + " joints");
        const std::vector<double> m = read(gs.inverseBindMatrices, label);
        for (size_t j = 0; j < skin.joints.size(); ++j) {
          float* dst = glm::value_ptr(skin.inverseBindMatrices[j]);
          for (size_t k = 0; k < 16; ++k) dst[k] = float(m[16 * j + k]);
          if (!finite(skin.inverseBindMatrices[j]))
            fail(ErrorKind::NonFinite, label + ": matrix " + std::to_string(j) + " is not finite");
        }
      }
      scene_.skins.push_back(std::move(skin));
    }
    for (size_t n = 0; n < scene_.nodes.size(); ++n) {
      const Node& node = scene_.nodes[n];
      if (node.skin < 0) continue;
      const size_t jointCount = scene_.skins[node.skin].joints.size();
      for (int m : node.meshes) {
        const Mesh& mesh = scene_.meshes[m];
        for (size_t v = 0; v < mesh.joints.size(); ++v)
          for (int k = 0; k < 4; ++k)
            if (mesh.weights[v][k] > 0.0f && mesh.joints[v][k] >= jointCount)
              fail(ErrorKind::IndexOutOfRange,
                   "node '" + node.name + "': mesh '" + mesh.name + "' vertex " +
                       std::to_string(v) + " uses joint " + std::to_string(mesh.joints[v][k]) +
                       " but skin " + std::to_string(node.skin) + " has " +
                       std::to_string(jointCount) + " joints");
      }
    }
  }

  // Animations: samplers checked (times scalar float, finite, strictly increasing; outputs
  // of the right type and count for the path and interpolation), channels mapped to nodes.
  void convertAnimations() {
    for (size_t ai = 0; ai < model_.animations.size(); ++ai) {
      const tinygltf::Animation& ga = model_.animations[ai];
      const std::string what = "animation " + std::to_string(ai);
      AnimationClip clip;
      clip.name = ga.name.empty() ? what : ga.name;
      std::vector<int> components(ga.samplers.size(), 0);  // 0: not used by a channel yet
      clip.samplers.resize(ga.samplers.size());
      for (size_t si = 0; si < ga.samplers.size(); ++si) {
        const tinygltf::AnimationSampler& gs = ga.samplers[si];
        const std::string label = what + " sampler " + std::to_string(si);
        AnimationSampler& s = clip.samplers[si];
        if (gs.interpolation == "LINEAR")
          s.interpolation = Interpolation::Linear;
        else if (gs.interpolation == "STEP")
          s.interpolation = Interpolation::Step;
        else if (gs.interpolation == "CUBICSPLINE")
          s.interpolation = Interpolation::CubicSpline;
        else
          fail(ErrorKind::Schema, label + ": unknown interpolation '" + gs.interpolation +
                                      "' (expected LINEAR, STEP or CUBICSPLINE)");
        requireFormat(gs.input, TINYGLTF_TYPE_SCALAR, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false,
                      label + " input");
        const std::vector<double> times = read(gs.input, label + " input");
        if (times.empty()) fail(ErrorKind::InvalidData, label + ": input has no keyframes");
        for (size_t k = 0; k < times.size(); ++k) {
          if (!std::isfinite(times[k]))
            fail(ErrorKind::NonFinite,
                 label + ": key time " + std::to_string(k) + " is not finite");
          if (k > 0 && !(times[k] > times[k - 1]))
            fail(ErrorKind::InvalidData, label + ": key times are not strictly increasing (key " +
                                             std::to_string(k) + " at " + std::to_string(times[k]) +
                                             " after " + std::to_string(times[k - 1]) + ")");
          s.times.push_back(float(times[k]));
        }
        clip.duration = std::max(clip.duration, s.times.back());
        accessor(gs.output, label + " output");  // exists; its format depends on the channel
      }
      for (size_t ci = 0; ci < ga.channels.size(); ++ci) {
        const tinygltf::AnimationChannel& gc = ga.channels[ci];
        const std::string label = what + " channel " + std::to_string(ci);
        if (gc.sampler < 0 || size_t(gc.sampler) >= ga.samplers.size())
          fail(ErrorKind::IndexOutOfRange, label + ": sampler " + std::to_string(gc.sampler) +
                                               " does not exist (animation has " +
                                               std::to_string(ga.samplers.size()) + " samplers)");
        if (gc.target_node < 0) continue;  // targets given by an extension: not supported
        if (size_t(gc.target_node) >= model_.nodes.size())
          fail(ErrorKind::IndexOutOfRange,
               label + ": target node " + std::to_string(gc.target_node) +
                   " does not exist (file has " + std::to_string(model_.nodes.size()) + " nodes)");
        AnimationChannel ch;
        ch.sampler = gc.sampler;
        int comps = 0;
        if (gc.target_path == "translation") {
          ch.path = AnimationPath::Translation;
          comps = 3;
        } else if (gc.target_path == "rotation") {
          ch.path = AnimationPath::Rotation;
          comps = 4;
        } else if (gc.target_path == "scale") {
          ch.path = AnimationPath::Scale;
          comps = 3;
        } else if (gc.target_path == "weights") {
          ch.path = AnimationPath::Weights;
        } else {
          warn(label + ": target path '" + gc.target_path + "' is not supported; ignored");
          continue;
        }
        const tinygltf::Node& target = model_.nodes[gc.target_node];
        if (ch.path != AnimationPath::Weights && target.matrix.size() == 16)
          fail(ErrorKind::InvalidData, label + ": node " + std::to_string(gc.target_node) +
                                           " is given by a matrix and cannot be animated");
        const tinygltf::AnimationSampler& gs = ga.samplers[gc.sampler];
        AnimationSampler& s = clip.samplers[gc.sampler];
        const size_t keys = s.times.size();
        const size_t perKey = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
        const tinygltf::Accessor& out = accessor(gs.output, label + " output");
        if (ch.path == AnimationPath::Weights) {
          requireFormat(gs.output, TINYGLTF_TYPE_SCALAR,
                        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                        true, label + " output");
          const size_t targets = target.mesh >= 0 && size_t(target.mesh) < model_.meshes.size() &&
                                         !model_.meshes[target.mesh].primitives.empty()
                                     ? model_.meshes[target.mesh].primitives[0].targets.size()
                                     : 0;
          if (targets == 0)
            fail(ErrorKind::InvalidData, label + ": animates morph weights of node " +
                                             std::to_string(gc.target_node) +
                                             ", which has no morph targets");
          comps = int(targets);
        } else {
          requireFormat(gs.output, comps == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                        comps == 4
                            ? std::initializer_list<int>{TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                         TINYGLTF_COMPONENT_TYPE_BYTE,
                                                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                                         TINYGLTF_COMPONENT_TYPE_SHORT,
                                                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}
                            : std::initializer_list<int>{TINYGLTF_COMPONENT_TYPE_FLOAT},
                        comps == 4, label + " output");
        }
        const size_t expected = keys * perKey * (ch.path == AnimationPath::Weights ? comps : 1);
        if (out.count != expected)
          fail(ErrorKind::InvalidData, label + ": output accessor " + std::to_string(gs.output) +
                                           " has " + std::to_string(out.count) + " elements, but " +
                                           std::to_string(keys) + " key times" +
                                           (perKey == 3 ? " (CUBICSPLINE: 3 per key)" : "") +
                                           (ch.path == AnimationPath::Weights
                                                ? " x " + std::to_string(comps) + " morph targets"
                                                : std::string()) +
                                           " need " + std::to_string(expected));
        if (components[gc.sampler] != 0 && components[gc.sampler] != comps)
          fail(ErrorKind::InvalidData, label + ": sampler " + std::to_string(gc.sampler) +
                                           " is shared by channels of different types");
        if (components[gc.sampler] == 0) {
          components[gc.sampler] = comps;
          s.components = comps;
          const std::vector<double> values = read(gs.output, label + " output");
          s.values.reserve(values.size());
          for (double v : values) {
            if (!std::isfinite(v))
              fail(ErrorKind::NonFinite, label + ": output values are not finite");
            s.values.push_back(float(v));
          }
        }
        ch.node = sceneNode_[gc.target_node];
        if (ch.node < 0) continue;  // node not in the displayed scene
        clip.channels.push_back(ch);
      }
      // Samplers no channel uses keep no values; give them nothing to sample.
      for (size_t si = 0; si < clip.samplers.size(); ++si)
        if (components[si] == 0) clip.samplers[si].times.clear();
      scene_.animations.push_back(std::move(clip));
    }
  }

  // Scene meshes for a glTF mesh (one per drawable primitive), converted on first use so that
  // instances share them.
  std::vector<int> meshesOf(int meshIndex, const std::string& what) {
    if (size_t(meshIndex) >= model_.meshes.size())
      fail(ErrorKind::IndexOutOfRange, what + ": mesh " + std::to_string(meshIndex) +
                                           " does not exist (file has " +
                                           std::to_string(model_.meshes.size()) + " meshes)");
    if (!meshCache_[meshIndex]) {
      std::vector<int> meshes;
      const tinygltf::Mesh& gm = model_.meshes[meshIndex];
      for (size_t p = 0; p < gm.primitives.size(); ++p)
        if (std::optional<Mesh> mesh = convertPrimitive(meshIndex, p)) {
          scene_.meshes.push_back(std::move(*mesh));
          meshes.push_back(static_cast<int>(scene_.meshes.size()) - 1);
        }
      meshCache_[meshIndex] = std::move(meshes);
    }
    return *meshCache_[meshIndex];
  }

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail(ErrorKind::IndexOutOfRange, what + ": accessor " + std::to_string(index) +
                                           " does not exist (file has " +
                                           std::to_string(model_.accessors.size()) + " accessors)");
    return model_.accessors[index];
  }

  // Checks an accessor's element type and component type; integer components must be
  // normalised where `normalisedIntegers` says so (texture coordinates).
  void requireFormat(int index, int type, std::initializer_list<int> componentTypes,
                     bool normalisedIntegers, const std::string& what) const {
    const tinygltf::Accessor& a = accessor(index, what);
    const bool typeOk = a.type == type;
    const bool componentOk = std::find(componentTypes.begin(), componentTypes.end(),
                                       a.componentType) != componentTypes.end();
    if (!typeOk || !componentOk) {
      std::string allowed;
      for (int ct : componentTypes) {
        if (!allowed.empty()) allowed += '/';
        allowed += componentTypeName(ct);
      }
      fail(ErrorKind::Schema, what + ": accessor " + std::to_string(index) + " is " +
                                  typeName(a.type) + " of " + componentTypeName(a.componentType) +
                                  ", expected " + typeName(type) + " of " + allowed);
    }
    const bool integer = a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT;
    if (integer && a.normalized != normalisedIntegers)
      fail(ErrorKind::Schema, what + ": accessor " + std::to_string(index) + " must " +
                                  (normalisedIntegers ? "" : "not ") + "be normalized");
  }

  // Bounds-checked view of `count` elements at `byteOffset` in a bufferView. `strided` is false
  // for sparse data, which is always tightly packed.
  Elements elements(int viewIndex, size_t byteOffset, size_t count, int componentType,
                    size_t components, bool strided, const std::string& what) const {
    if (viewIndex < 0 || size_t(viewIndex) >= model_.bufferViews.size())
      fail(ErrorKind::IndexOutOfRange,
           what + ": bufferView " + std::to_string(viewIndex) + " does not exist (file has " +
               std::to_string(model_.bufferViews.size()) + " bufferViews)");
    const tinygltf::BufferView& view = model_.bufferViews[viewIndex];
    const std::string viewName = "bufferView " + std::to_string(viewIndex);
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
      fail(ErrorKind::IndexOutOfRange, what + ": " + viewName + " uses buffer " +
                                           std::to_string(view.buffer) +
                                           ", which does not exist (file has " +
                                           std::to_string(model_.buffers.size()) + " buffers)");
    const std::vector<unsigned char>& data = model_.buffers[view.buffer].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
      fail(ErrorKind::IndexOutOfRange,
           what + ": " + viewName + " (bytes " + std::to_string(view.byteOffset) + " to " +
               std::to_string(view.byteOffset + view.byteLength) +
               ") extends past the end of buffer " + std::to_string(view.buffer) + " (" +
               std::to_string(data.size()) + " bytes)");
    const int componentSize = tinygltf::GetComponentSizeInBytes(uint32_t(componentType));
    if (componentSize <= 0)
      fail(ErrorKind::Schema, what + ": unknown component type " + std::to_string(componentType));
    const size_t elementSize = size_t(componentSize) * components;
    const size_t stride = strided && view.byteStride > 0 ? view.byteStride : elementSize;
    if (stride < elementSize)
      fail(ErrorKind::InvalidData, what + ": " + viewName + " has byteStride " +
                                       std::to_string(stride) + ", less than one element (" +
                                       std::to_string(elementSize) + " bytes)");
    // Sizes are bounded (counts and offsets < 2^31 by the schema check, stride <= 252), so
    // none of this overflows a 64-bit size_t.
    const size_t end = count == 0 ? byteOffset : byteOffset + (count - 1) * stride + elementSize;
    if (end > view.byteLength)
      fail(ErrorKind::IndexOutOfRange, what + ": needs bytes " + std::to_string(byteOffset) +
                                           " to " + std::to_string(end) + " of " + viewName +
                                           ", which has only " + std::to_string(view.byteLength));
    return {data.data() + view.byteOffset + byteOffset, stride, componentType,
            size_t(componentSize)};
  }

  // All components of an accessor (count x components), sparse substitution and
  // normalisation applied. The caller has checked the index and format.
  std::vector<double> read(int index, const std::string& what) const {
    const tinygltf::Accessor& a = model_.accessors[index];
    const std::string name = what + " (accessor " + std::to_string(index) + ")";
    const size_t components = size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
    // Check the data exists before allocating for it: `count` is only a claim.
    std::optional<Elements> base;
    if (a.bufferView >= 0)
      base = elements(a.bufferView, a.byteOffset, a.count, a.componentType, components, true, name);
    std::vector<double> values(a.count * components, 0.0);  // no bufferView: zeros
    if (base)
      for (size_t e = 0; e < a.count; ++e)
        for (size_t c = 0; c < components; ++c) values[e * components + c] = base->get(e, c);

    if (a.sparse.isSparse) {
      const auto& sp = a.sparse;
      const int indexType = sp.indices.componentType;
      if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
          indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(ErrorKind::Schema, name + ": sparse indices must be UNSIGNED_BYTE/SHORT/INT, not " +
                                    std::string(componentTypeName(indexType)));
      const size_t n = size_t(sp.count);
      const Elements indices = elements(sp.indices.bufferView, size_t(sp.indices.byteOffset), n,
                                        indexType, 1, false, name + " sparse indices");
      const Elements replacements =
          elements(sp.values.bufferView, size_t(sp.values.byteOffset), n, a.componentType,
                   components, false, name + " sparse values");
      for (size_t i = 0; i < n; ++i) {
        const double target = indices.get(i, 0);
        if (target >= double(a.count))
          fail(ErrorKind::IndexOutOfRange,
               name + ": sparse index " + std::to_string(size_t(target)) +
                   " is past the accessor's " + std::to_string(a.count) + " elements");
        for (size_t c = 0; c < components; ++c)
          values[size_t(target) * components + c] = replacements.get(i, c);
      }
    }
    if (a.normalized)
      for (double& v : values) v = normalise(v, a.componentType);
    return values;
  }

  // One glTF primitive as a triangle mesh; nullopt (with a warning) for primitives that are
  // not drawn: points and lines, or nothing usable left after sanitising.
  std::optional<Mesh> convertPrimitive(int meshIndex, size_t primIndex) {
    const tinygltf::Mesh& gm = model_.meshes[meshIndex];
    const tinygltf::Primitive& prim = gm.primitives[primIndex];
    const std::string what = "mesh " + std::to_string(meshIndex) +
                             (gm.name.empty() ? "" : " '" + gm.name + "'") + " primitive " +
                             std::to_string(primIndex);
    switch (prim.mode) {
      case TINYGLTF_MODE_TRIANGLES:
      case TINYGLTF_MODE_TRIANGLE_STRIP:
      case TINYGLTF_MODE_TRIANGLE_FAN:
        break;
      case TINYGLTF_MODE_POINTS:
      case TINYGLTF_MODE_LINE:
      case TINYGLTF_MODE_LINE_LOOP:
      case TINYGLTF_MODE_LINE_STRIP:
        warn(what + ": points and lines are not rendered; skipped");
        return std::nullopt;
      default:
        fail(ErrorKind::Schema, what + ": unknown primitive mode " + std::to_string(prim.mode));
    }

    // Every attribute must exist and have one element per vertex (the spec says so, and a
    // mismatch means the file is not what its writer meant).
    auto position = prim.attributes.find("POSITION");
    if (position == prim.attributes.end())
      fail(ErrorKind::InvalidData, what + " has no POSITION attribute");
    const size_t vertexCount = accessor(position->second, what + " POSITION").count;
    for (const auto& [attribute, index] : prim.attributes) {
      const size_t n = accessor(index, what + " " + attribute).count;
      if (n != vertexCount)
        fail(ErrorKind::InvalidData,
             what + ": attribute " + attribute + " (accessor " + std::to_string(index) + ") has " +
                 std::to_string(n) + " elements but POSITION has " + std::to_string(vertexCount));
    }

    Mesh mesh;
    mesh.name = gm.primitives.size() > 1 || gm.name.empty() ? what : gm.name;
    mesh.vertices.resize(vertexCount);
    requireFormat(position->second, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false,
                  what + " POSITION");
    const std::vector<double> p = read(position->second, what + " POSITION");
    for (size_t v = 0; v < vertexCount; ++v)
      mesh.vertices[v].position =
          glm::vec3(float(p[3 * v]), float(p[3 * v + 1]), float(p[3 * v + 2]));

    // Normals: normalise usable ones; zero marks the rest for processMesh to recompute (the
    // Vertex default would otherwise pass for a valid normal).
    bool hasNormals = false;
    if (auto normal = prim.attributes.find("NORMAL"); normal != prim.attributes.end()) {
      hasNormals = true;
      requireFormat(normal->second, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false,
                    what + " NORMAL");
      const std::vector<double> n = read(normal->second, what + " NORMAL");
      for (size_t v = 0; v < vertexCount; ++v) {
        const glm::vec3 dir{float(n[3 * v]), float(n[3 * v + 1]), float(n[3 * v + 2])};
        const float len = glm::length(dir);
        mesh.vertices[v].normal = std::isfinite(len) && len > 1e-6f ? dir / len : glm::vec3(0.0f);
      }
    } else {
      for (Vertex& v : mesh.vertices) v.normal = glm::vec3(0.0f);
    }

    if (auto uv = prim.attributes.find("TEXCOORD_0"); uv != prim.attributes.end()) {
      requireFormat(uv->second, TINYGLTF_TYPE_VEC2,
                    {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                    true, what + " TEXCOORD_0");
      const std::vector<double> t = read(uv->second, what + " TEXCOORD_0");
      for (size_t v = 0; v < vertexCount; ++v)
        mesh.vertices[v].uv = glm::vec2(float(t[2 * v]), float(t[2 * v + 1]));
    }

    readSkinAttributes(prim, mesh, what);
    readMorphTargets(prim, mesh, vertexCount, what);
    for (size_t t = 0; t < mesh.morphTargets.size(); ++t)
      mesh.morphWeights.push_back(t < gm.weights.size() ? float(gm.weights[t]) : 0.0f);

    std::vector<uint32_t> order;  // vertex order before triangulating strips and fans
    if (prim.indices >= 0) {
      requireFormat(prim.indices, TINYGLTF_TYPE_SCALAR,
                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                    false, what + " indices");
      const std::vector<double> idx = read(prim.indices, what + " indices");
      order.reserve(idx.size());
      for (size_t i = 0; i < idx.size(); ++i) {
        if (idx[i] >= double(vertexCount))
          fail(ErrorKind::IndexOutOfRange,
               what + ": index " + std::to_string(uint64_t(idx[i])) + " at position " +
                   std::to_string(i) + " of accessor " + std::to_string(prim.indices) +
                   " is past the last vertex (" + std::to_string(vertexCount) + " vertices)");
        order.push_back(uint32_t(idx[i]));
      }
    } else {
      order.resize(vertexCount);
      for (size_t v = 0; v < vertexCount; ++v) order[v] = uint32_t(v);
    }

    if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
      if (order.size() % 3 != 0)
        fail(ErrorKind::InvalidData, what + ": " + std::to_string(order.size()) +
                                         (prim.indices >= 0 ? " indices" : " vertices") +
                                         " do not form whole triangles (not a multiple of 3)");
      mesh.indices = std::move(order);
    } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      // Every other triangle is flipped so that all keep the strip's winding.
      for (size_t i = 0; i + 2 < order.size(); ++i) {
        if (i % 2 == 0)
          mesh.indices.insert(mesh.indices.end(), {order[i], order[i + 1], order[i + 2]});
        else
          mesh.indices.insert(mesh.indices.end(), {order[i + 1], order[i], order[i + 2]});
      }
    } else {  // fan around the first vertex
      for (size_t i = 1; i + 1 < order.size(); ++i)
        mesh.indices.insert(mesh.indices.end(), {order[i], order[i + 1], order[0]});
    }
    mesh.material = materialFor(prim.material, what);

    const MeshFixReport fix = processMesh(mesh);
    droppedNonFinite_ += fix.droppedNonFiniteTriangles;
    if (fix.droppedNonFiniteTriangles > 0)
      warn(what + ": dropped " + std::to_string(fix.droppedNonFiniteTriangles) +
           " triangles with non-finite (NaN/Inf) positions");
    if (fix.droppedDegenerateTriangles > 0)
      warn(what + ": dropped " + std::to_string(fix.droppedDegenerateTriangles) +
           " degenerate triangles");
    if (!hasNormals)
      warn(what + ": no normals in the file; computed from the triangles");
    else if (fix.recomputedNormals > 0)
      warn(what + ": recomputed " + std::to_string(fix.recomputedNormals) +
           " zero-length or non-finite normals");
    if (mesh.indices.empty()) {
      warn(what + ": no usable triangles left; skipped");
      return std::nullopt;
    }
    return mesh;
  }

  // JOINTS_0 / WEIGHTS_0: u8/u16 joints, float or normalised u8/u16 weights. Weights are
  // made non-negative and finite, then renormalised to sum 1; all-zero rows stay zero (the
  // vertex keeps its bind pose).
  void readSkinAttributes(const tinygltf::Primitive& prim, Mesh& mesh, const std::string& what) {
    auto joints = prim.attributes.find("JOINTS_0");
    auto weights = prim.attributes.find("WEIGHTS_0");
    if (joints == prim.attributes.end() && weights == prim.attributes.end()) return;
    if (joints == prim.attributes.end() || weights == prim.attributes.end())
      fail(ErrorKind::InvalidData,
           what + ": has " + (joints == prim.attributes.end() ? "WEIGHTS_0" : "JOINTS_0") +
               " without " + (joints == prim.attributes.end() ? "JOINTS_0" : "WEIGHTS_0"));
    requireFormat(joints->second, TINYGLTF_TYPE_VEC4,
                  {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                  false, what + " JOINTS_0");
    const tinygltf::Accessor& wa = accessor(weights->second, what + " WEIGHTS_0");
    requireFormat(weights->second, TINYGLTF_TYPE_VEC4,
                  {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                  wa.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT, what + " WEIGHTS_0");
    const std::vector<double> j = read(joints->second, what + " JOINTS_0");
    const std::vector<double> w = read(weights->second, what + " WEIGHTS_0");
    const size_t n = mesh.vertices.size();
    mesh.joints.resize(n);
    mesh.weights.resize(n);
    size_t zero = 0;
    for (size_t v = 0; v < n; ++v) {
      glm::vec4 wv(0.0f);
      float sum = 0.0f;
      for (int k = 0; k < 4; ++k) {
        mesh.joints[v][k] = uint32_t(j[4 * v + k]);
        const double x = w[4 * v + k];
        wv[k] = std::isfinite(x) && x > 0.0 ? float(x) : 0.0f;
        sum += wv[k];
      }
      if (sum > 0.0f && std::isfinite(sum))
        wv /= sum;
      else {
        wv = glm::vec4(0.0f);
        ++zero;
      }
      mesh.weights[v] = wv;
    }
    if (zero > 0)
      warn(what + ": " + std::to_string(zero) +
           " vertices have no skin weight; they keep their bind pose");
  }

  // Morph targets: POSITION and NORMAL deltas (float VEC3), one per vertex. Other target
  // attributes (TANGENT, ...) are ignored.
  void readMorphTargets(const tinygltf::Primitive& prim, Mesh& mesh, size_t vertexCount,
                        const std::string& what) {
    for (size_t t = 0; t < prim.targets.size(); ++t) {
      MorphTarget target;
      for (const auto& [attribute, index] : prim.targets[t]) {
        if (attribute != "POSITION" && attribute != "NORMAL") continue;
        const std::string label = what + " morph target " + std::to_string(t) + " " + attribute;
        requireFormat(index, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false, label);
        if (accessor(index, label).count != vertexCount)
          fail(ErrorKind::InvalidData, label + ": accessor " + std::to_string(index) + " has " +
                                           std::to_string(accessor(index, label).count) +
                                           " elements but POSITION has " +
                                           std::to_string(vertexCount));
        const std::vector<double> d = read(index, label);
        std::vector<glm::vec3>& dst =
            attribute == "POSITION" ? target.positionDeltas : target.normalDeltas;
        dst.resize(vertexCount);
        for (size_t v = 0; v < vertexCount; ++v) {
          dst[v] = glm::vec3(float(d[3 * v]), float(d[3 * v + 1]), float(d[3 * v + 2]));
          if (!std::isfinite(dst[v].x) || !std::isfinite(dst[v].y) || !std::isfinite(dst[v].z))
            fail(ErrorKind::NonFinite, label + ": delta " + std::to_string(v) + " is not finite");
        }
      }
      mesh.morphTargets.push_back(std::move(target));
    }
  }

  std::string path_;
  tinygltf::Model model_;
  Scene scene_;
  std::vector<int> parent_;     // per glTF node, -1 for roots
  std::vector<int> sceneNode_;  // glTF node -> scene node, -1 when not in the scene
  std::vector<std::optional<std::vector<int>>> meshCache_;  // glTF mesh -> scene meshes
  std::vector<int> imageTexture_;  // glTF image -> scene texture, -1: none yet
  int defaultMaterial_ = -1;       // for primitives without a material
  size_t droppedNonFinite_ = 0;    // triangles, over all primitives
};

}  // namespace

Scene loadGltf(const std::string& path) {
  return GltfLoader(path).load();
}

}  // namespace gi
