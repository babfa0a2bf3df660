// JSON scene files (assets/scenes/*.json) and loadScene's dispatch on the file extension.
//
// Format (every key optional unless marked required; unknown keys are errors; "//" and "/* */"
// comments are allowed; documented with examples in assets/scenes/README.md):
//
// {
//   "description": "free text",
//   "include_default_scene": false,        // start from the built-in Cornell-box room
//   "models": [                            // each becomes a root node with this transform
//     { "file": "model.gltf",              // .gltf .glb .obj .ply; relative to this file's folder,
//                                          // absolute, or starting with ${ASSIMP_MODELS}
//       "name": "engine",
//       "translation": [0, 0, 0],
//       "rotation": [0, 0, 0, 1],          // quaternion [x, y, z, w], or Euler degrees [x, y, z]
//                                          // applied about X, then Y, then Z (fixed axes)
//       "scale": 1.0,                      // or [sx, sy, sz]; no zero components
//       "clip": "Walk" | 0,                // keep only this animation clip of the file
//       "animation": { ... },              // see below
//       "grid": { "counts": [nx, ny, nz], "spacing": [dx, dy, dz] } },  // nx*ny*nz copies (at most
//       100000)
//                                          // sharing the meshes, offset by i*dx, j*dy, k*dz
//                                          // (world units, added to the translation); not
//                                          // with animation, skins, cameras or lights
//     { "primitive": "plane" | "box" | "sphere",   // instead of "file"
//       "size": 4.0,                       // plane: number or [x, z]; box: number or [x, y, z]
//       "segments": 1,                     // box: s x s quads per face (1..64)
//       "radius": 0.5, "segments": 32, "rings": 16,  // sphere only
//       "material": { "name": "...", "base_color": [r, g, b(, a)], "emission": [r, g, b],
//                     "roughness": 0.8, "metallic": 0.0, "double_sided": false },
//       (emission leaves the side the normal points to; "double_sided": both sides)
//       "name", "translation", "rotation", "scale", "animation" as above }
//   ],
//   "camera": { "position": [x, y, z] (required), "target": [x, y, z] (required),
//               "up": [0, 1, 0], "yfov_deg": 45, "near": 0.05, "far": 1000, "name": "...",
//               "animation": { ... } },
//   "lights": [ { "type": "point" | "spot" | "directional" (required), "name": "...",
//                 "position": [x, y, z] (required for point and spot),
//                 "direction": [0, -1, 0] (spot and directional: where the light travels),
//                 "color": [1, 1, 1], "intensity": 1 (candela; lux for directional),
//                 "range": 0 (0: infinite), "inner_cone_deg": 0, "outer_cone_deg": 45,
//                 "casts_shadows": true, "animation": { ... } } ],
//   "environment": { "type": "sky" | "constant" | "map", "intensity": 1,
//                    "color": [r, g, b] (constant only),
//                    "file": "sky.hdr" (map only, required: equirectangular Radiance .hdr,
//                            relative to the scene file; ${ASSIMP_MODELS} expands),
//                    "zenith_color", "horizon_color", "ground_color": [r, g, b] (sky only) },
//   "effects": [ "ssao", { "name": "bloom", "settings": { ... } } ],
//   "regions": [ { "name": "floor", "min": [x, y, z], "max": [x, y, z] } ]   // world boxes,
//                                          // scored apart by gi-bench (names unique)
// }
//
// "animation" (models, lights, camera): a looping clip of its own driving the entry's node:
//   { "translation" | "rotation" | "scale" | "direction" (spot/directional lights):
//       { "times": [...] (>= 0, strictly increasing), "values": [...] (one per key; in-tangent,
//         value, out-tangent per key for cubicspline), "interpolation": "linear" | "step" |
//         "cubicspline" },
//     "orbit": { "center": [x, y, z] (camera default: its target), "axis": [0, 1, 0],
//                "period": seconds } }
// Tracks replace that part of the entry's own transform (translation keys are absolute);
// parts without a track keep the entry's value. An orbit turns the whole transform about the
// axis through the centre (a camera orbiting its target keeps looking at it).
//
// ${ASSIMP_MODELS} expands to $ASSIMP_MODELS, else /usr/share/assimp/models (Debian's
// assimp-testmodels). It is the only variable: a scene names every other file relative to itself,
// so a scene folder with its models (assets/scenes + assets/models) stands alone.
//
// Without a "camera" (and no camera in the models) the scene is framed automatically; without
// any light a sun is added (addDefaultCameraAndLight). The JSON camera becomes the active one.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/input_file.h"
#include "gi/scene_io.h"
#include "json_check.h"
#include "scene_io_util.h"

namespace gi {
namespace {

namespace fs = std::filesystem;
using detail::JsonObject;
using nlohmann::json;

std::string indexed(const std::string& list, size_t i) {
  return list + "[" + std::to_string(i) + "]";
}

// Expands a leading ${ASSIMP_MODELS}; other ${...} are errors.
fs::path expandModelPath(const std::string& file, const fs::path& sceneDir, const JsonObject& o) {
  if (file.rfind("${", 0) != 0) {
    fs::path p(file);
    return p.is_absolute() ? p : sceneDir / p;
  }
  const size_t close = file.find('}');
  if (close == std::string::npos) o.schemaError("file", "unterminated '${' in '" + file + "'");
  const std::string var = file.substr(2, close - 2);
  if (var != "ASSIMP_MODELS")
    o.schemaError("file", "unknown variable '${" + var +
                              "}' (known: ${ASSIMP_MODELS}; name other files relative to the "
                              "scene file)");
  std::string rest = file.substr(close + 1);
  while (!rest.empty() && (rest.front() == '/' || rest.front() == '\\')) rest.erase(0, 1);
  const char* env = std::getenv("ASSIMP_MODELS");
  return fs::path(env && *env ? env : "/usr/share/assimp/models") / rest;
}

glm::mat4 readTransform(const JsonObject& o) {
  glm::mat4 t = glm::translate(glm::mat4(1.0f), o.vec3("translation").value_or(glm::vec3(0)));
  if (auto r = o.numbers("rotation", {3, 4})) {
    if (r->size() == 4) {
      glm::quat q((*r)[3], (*r)[0], (*r)[1], (*r)[2]);  // JSON order is x, y, z, w (as glTF)
      if (glm::length(q) < 1e-6f) o.invalid("rotation", "quaternion has zero length");
      t *= glm::mat4_cast(glm::normalize(q));
    } else {
      t = glm::rotate(t, glm::radians((*r)[2]), glm::vec3(0, 0, 1));
      t = glm::rotate(t, glm::radians((*r)[1]), glm::vec3(0, 1, 0));
      t = glm::rotate(t, glm::radians((*r)[0]), glm::vec3(1, 0, 0));
    }
  }
  if (o.has("scale")) {
    glm::vec3 s(1.0f);
    if (o.at("scale").is_number())
      s = glm::vec3(*o.number("scale"));
    else
      s = *o.vec3("scale");
    if (s.x == 0.0f || s.y == 0.0f || s.z == 0.0f) o.invalid("scale", "must not be zero");
    t = glm::scale(t, s);
  }
  return t;
}

// A rotation given as a quaternion [x, y, z, w] (normalised) or Euler degrees [x, y, z] (about
// X, then Y, then Z: the rotation readTransform builds); `where` names it in errors.
glm::quat rotationOf(const std::vector<float>& r, const std::string& where,
                     const std::string& file) {
  if (r.size() == 4) {
    const glm::quat q(r[3], r[0], r[1], r[2]);
    if (!(glm::length(q) >= 1e-6f))
      throw Error(ErrorKind::InvalidData, file, where + ": quaternion has zero length");
    return glm::normalize(q);
  }
  return glm::angleAxis(glm::radians(r[2]), glm::vec3(0, 0, 1)) *
         glm::angleAxis(glm::radians(r[1]), glm::vec3(0, 1, 0)) *
         glm::angleAxis(glm::radians(r[0]), glm::vec3(1, 0, 0));
}

// An entry's own transform as translation, rotation, scale: what its animation starts from.
struct TRS {
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  glm::mat4 matrix() const {
    return glm::translate(glm::mat4(1.0f), translation) * glm::mat4_cast(rotation) *
           glm::scale(glm::mat4(1.0f), scale);
  }
};

// The TRS of a model entry (readTransform has validated the keys already).
TRS readTRS(const JsonObject& o) {
  TRS trs;
  trs.translation = o.vec3("translation").value_or(glm::vec3(0.0f));
  if (auto r = o.numbers("rotation", {3, 4}))
    trs.rotation = rotationOf(*r, o.pathOf("rotation"), o.file());
  if (o.has("scale"))
    trs.scale = o.at("scale").is_number() ? glm::vec3(*o.number("scale")) : *o.vec3("scale");
  return trs;
}

// TRS of a rigid matrix (a light's or camera's inverse look-at matrix).
TRS rigidTRS(const glm::mat4& m) {
  TRS trs;
  trs.translation = glm::vec3(m[3]);
  trs.rotation = glm::normalize(glm::quat_cast(glm::mat3(m)));
  return trs;
}

// Rotation turning a node's -z (where lights shine) towards `dir` (non-zero): as readLights
// orients light nodes.
glm::quat rotationTowards(const glm::vec3& dir) {
  const glm::vec3 d = glm::normalize(dir);
  const glm::vec3 up = std::abs(d.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  return rigidTRS(glm::inverse(glm::lookAt(glm::vec3(0.0f), d, up))).rotation;
}

// The shortest rotation taking unit vector `a` to unit vector `b` (half a turn about some axis
// perpendicular to `a` when they are opposite).
glm::quat shortestArc(const glm::vec3& a, const glm::vec3& b) {
  const float d = glm::dot(a, b);
  if (d < -0.999999f) {
    glm::vec3 axis = glm::cross(glm::vec3(1, 0, 0), a);
    if (glm::length(axis) < 1e-3f) axis = glm::cross(glm::vec3(0, 1, 0), a);
    return glm::angleAxis(glm::pi<float>(), glm::normalize(axis));
  }
  const glm::vec3 c = glm::cross(a, b);
  return glm::normalize(glm::quat(1.0f + d, c.x, c.y, c.z));
}

glm::vec3 nonNegativeColor(const JsonObject& o, const char* key, glm::vec3 fallback) {
  glm::vec3 c = o.vec3(key).value_or(fallback);
  if (c.x < 0 || c.y < 0 || c.z < 0) o.invalid(key, "colour components must not be negative");
  return c;
}

float nonNegative(const JsonObject& o, const char* key, float fallback) {
  float v = o.number(key).value_or(fallback);
  if (v < 0.0f) o.invalid(key, "must not be negative");
  return v;
}

Material readMaterial(const JsonObject& o) {
  o.allowOnly({"name", "base_color", "emission", "roughness", "metallic", "double_sided"});
  Material m;
  m.name = o.string("name").value_or("material");
  if (auto c = o.numbers("base_color", {3, 4})) {
    for (float v : *c)
      if (v < 0.0f || v > 1.0f) o.invalid("base_color", "components must be in [0, 1]");
    m.baseColor = glm::vec4((*c)[0], (*c)[1], (*c)[2], c->size() == 4 ? (*c)[3] : 1.0f);
  }
  m.emission = nonNegativeColor(o, "emission", glm::vec3(0.0f));
  m.roughness = o.number("roughness").value_or(m.roughness);
  m.metallic = o.number("metallic").value_or(m.metallic);
  m.doubleSided = o.boolean("double_sided").value_or(false);
  if (m.roughness < 0 || m.roughness > 1) o.invalid("roughness", "must be in [0, 1]");
  if (m.metallic < 0 || m.metallic > 1) o.invalid("metallic", "must be in [0, 1]");
  return m;
}

// A "primitive" model as a one-mesh scene (`file`: the scene file, for messages).
Scene makePrimitive(const JsonObject& o, const std::string& file) {
  const std::string kind = o.requireString("primitive");
  Mesh mesh;
  if (kind == "plane" || kind == "box") {
    o.allowOnly({"primitive", "name", "translation", "rotation", "scale", "size", "material",
                 "animation", "grid", "segments"});
    if (kind == "plane" && o.has("segments"))
      o.schemaError("segments", "unknown key (a plane has none; a box's faces take segments)");
    glm::vec3 size(1.0f);
    if (o.has("size")) {
      if (o.at("size").is_number())
        size = glm::vec3(*o.number("size"));
      else if (kind == "plane") {
        auto xz = *o.numbers("size", {2});
        size = glm::vec3(xz[0], 1.0f, xz[1]);
      } else {
        size = *o.vec3("size");
      }
    }
    if (size.x <= 0 || size.y <= 0 || size.z <= 0) o.invalid("size", "must be positive");
    const int segments = o.integer("segments").value_or(1);
    if (segments < 1 || segments > 64) o.invalid("segments", "must be in [1, 64]");
    mesh = kind == "plane" ? detail::makePlane(size.x, size.z) : detail::makeBox(size, segments);
  } else if (kind == "sphere") {
    o.allowOnly({"primitive", "name", "translation", "rotation", "scale", "radius", "segments",
                 "rings", "material", "animation", "grid"});
    const float radius = o.number("radius").value_or(0.5f);
    const int segments = o.integer("segments").value_or(32);
    const int rings = o.integer("rings").value_or(16);
    if (radius <= 0) o.invalid("radius", "must be positive");
    if (segments < 3 || segments > 4096) o.invalid("segments", "must be in [3, 4096]");
    if (rings < 2 || rings > 4096) o.invalid("rings", "must be in [2, 4096]");
    mesh = detail::makeSphere(radius, segments, rings);
  } else {
    o.schemaError("primitive", "unknown primitive '" + kind + "' (plane, box or sphere)");
  }
  Scene s;
  s.materials.push_back(o.has("material")
                            ? readMaterial(JsonObject(o.at("material"), o.pathOf("material"), file))
                            : Material{.name = kind});
  mesh.material = 0;
  s.meshes.push_back(std::move(mesh));
  s.nodes[s.addNode(kind, glm::mat4(1.0f))].meshes.push_back(0);
  return s;
}

class SceneJsonLoader {
 public:
  explicit SceneJsonLoader(const std::string& path) : path_(path) {}

  Scene load() {
    const std::string text = detail::readTextFile(path_);
    const json root = parseJsonText(text, path_, /*allowComments=*/true);
    JsonObject top(root, "", path_);
    top.allowOnly({"description", "include_default_scene", "models", "camera", "lights",
                   "environment", "effects", "regions"});
    top.string("description");  // type check only
    if (top.boolean("include_default_scene").value_or(false)) scene_ = makeDefaultScene();
    scene_.sourcePath = path_;

    if (top.has("models")) readModels(top);
    if (top.has("camera")) readCamera(JsonObject(top.at("camera"), "camera", path_));
    if (top.has("lights")) readLights(top);
    if (top.has("environment"))
      readEnvironment(JsonObject(top.at("environment"), "environment", path_));
    if (top.has("effects")) readEffects(top);
    if (top.has("regions")) readRegions(top);

    addDefaultCameraAndLight(scene_);  // also updates the world transforms
    return std::move(scene_);
  }

 private:
  const json& array(const JsonObject& o, const char* key) const {
    const json& v = o.at(key);
    if (!v.is_array()) o.schemaError(key, "expected an array");
    return v;
  }

  void readModels(const JsonObject& top) {
    const json& models = array(top, "models");
    const fs::path sceneDir = fs::path(path_).parent_path();
    for (size_t i = 0; i < models.size(); ++i) {
      JsonObject m(models[i], indexed("models", i), path_);
      if (m.has("file") == m.has("primitive"))
        m.schemaError("file", "each model needs exactly one of \"file\" and \"primitive\"");
      Scene model;
      std::string name;
      if (m.has("primitive")) {
        model = makePrimitive(m, path_);
        name = m.string("name").value_or(*m.string("primitive"));
      } else {
        m.allowOnly(
            {"file", "name", "translation", "rotation", "scale", "clip", "animation", "grid"});
        const std::string file = m.requireString("file");
        const fs::path resolved = expandModelPath(file, sceneDir, m);
        model = loadModel(resolved.string(), m);
        name = m.string("name").value_or(resolved.stem().string());
        if (m.has("clip")) selectClip(m, model, resolved.filename().string());
      }
      const size_t clipsBefore = scene_.animations.size(), skinsBefore = scene_.skins.size();
      const size_t camerasBefore = scene_.cameras.size(), lightsBefore = scene_.lights.size();
      const glm::mat4 transform = readTransform(m);
      const int node = detail::mergeScene(scene_, std::move(model), name, transform);
      if (m.has("animation")) readAnimation(m, node, readTRS(m), Target::Model);
      if (m.has("grid")) {
        if (m.has("animation") || scene_.animations.size() != clipsBefore ||
            scene_.skins.size() != skinsBefore || scene_.cameras.size() != camerasBefore ||
            scene_.lights.size() != lightsBefore)
          m.invalid("grid", "a model with animation, skins, cameras or lights cannot be repeated");
        repeatOnGrid(JsonObject(m.at("grid"), m.pathOf("grid"), path_), node, transform);
      }
    }
  }

  // "grid": copies of the model's node tree `root` (placed by `transform`) sharing its meshes,
  // one per cell but the first, which `root` is.
  void repeatOnGrid(const JsonObject& g, int root, const glm::mat4& transform) {
    g.allowOnly({"counts", "spacing"});
    if (!g.has("counts")) g.schemaError("counts", "missing required key");
    const std::vector<float> counts = *g.numbers("counts", {3});
    const glm::vec3 spacing = g.vec3("spacing").value_or(glm::vec3(1.0f));
    uint64_t total = 1;
    int n[3];
    for (int a = 0; a < 3; ++a) {
      if (!(counts[a] >= 1.0f) || counts[a] != std::floor(counts[a]) || counts[a] > 1e5f)
        g.invalid("counts", "each count must be a whole number in [1, 100000]");
      n[a] = int(counts[a]);
      total *= uint64_t(n[a]);
    }
    if (total > 100000) g.invalid("counts", "more than 100000 copies in all");
    for (int i = 0; i < n[0]; ++i)
      for (int j = 0; j < n[1]; ++j)
        for (int k = 0; k < n[2]; ++k) {
          if (i == 0 && j == 0 && k == 0) continue;  // the model itself
          const glm::vec3 offset = glm::vec3(float(i), float(j), float(k)) * spacing;
          const int copy = scene_.addNode(scene_.nodes[root].name,
                                          glm::translate(glm::mat4(1.0f), offset) * transform);
          scene_.nodes[copy].meshes = scene_.nodes[root].meshes;
          for (int child : std::vector<int>(scene_.nodes[root].children)) cloneTree(child, copy);
        }
  }

  // Appends a copy of node `src` and its descendants under `parent` (same meshes).
  void cloneTree(int src, int parent) {
    Node n = scene_.nodes[src];
    const std::vector<int> children = n.children;
    n.children.clear();
    n.parent = parent;
    const int copy = int(scene_.nodes.size());
    scene_.nodes.push_back(std::move(n));
    scene_.nodes[parent].children.push_back(copy);
    for (int child : children) cloneTree(child, copy);
  }

  // "clip": keeps only the named (or numbered) animation clip of a model file.
  void selectClip(const JsonObject& m, Scene& model, const std::string& file) const {
    const json& c = m.at("clip");
    std::string names;
    for (const AnimationClip& a : model.animations)
      names += (names.empty() ? "" : ", ") + ("'" + a.name + "'");
    const std::string available =
        names.empty() ? " (it has no animation clips)" : " (clips: " + names + ")";
    size_t keep = model.animations.size();
    if (c.is_string()) {
      const std::string want = c.get<std::string>();
      for (size_t i = 0; i < model.animations.size() && keep == model.animations.size(); ++i)
        if (model.animations[i].name == want) keep = i;
      if (keep == model.animations.size())
        m.invalid("clip", "no clip named '" + want + "' in " + file + available);
    } else if (c.is_number_integer()) {
      const int index = *m.integer("clip");
      if (index < 0 || size_t(index) >= model.animations.size())
        m.invalid("clip", "no clip " + std::to_string(index) + " in " + file + available);
      keep = size_t(index);
    } else {
      m.schemaError("clip", "expected a clip name or index");
    }
    std::vector<AnimationClip> kept{std::move(model.animations[keep])};
    model.animations = std::move(kept);
  }

  // ---- "animation" of a model, light or camera entry ------------------------------------

  enum class Target { Model, Camera, Light, DirectedLight };
  enum class Track { Translation, Rotation, Scale, Direction };

  // Keys of one track: "times" (seconds, >= 0, strictly increasing), "values" (one per key, or
  // in-tangent, value, out-tangent per key for cubicspline) and "interpolation".
  AnimationSampler readTrack(const JsonObject& t, Track track) const {
    t.allowOnly({"times", "values", "interpolation"});
    AnimationSampler s;
    const std::string interp = t.string("interpolation").value_or("linear");
    if (interp == "linear")
      s.interpolation = Interpolation::Linear;
    else if (interp == "step")
      s.interpolation = Interpolation::Step;
    else if (interp == "cubicspline")
      s.interpolation = Interpolation::CubicSpline;
    else
      t.schemaError("interpolation",
                    "unknown interpolation '" + interp + "' (linear, step or cubicspline)");
    const bool cubic = s.interpolation == Interpolation::CubicSpline;
    if (cubic && track == Track::Direction)
      t.schemaError("interpolation", "direction keys take linear or step interpolation");

    if (!t.has("times")) t.schemaError("times", "missing required key");
    s.times = detail::numberList(t.at("times"), t.pathOf("times"), path_);
    if (s.times.empty()) t.invalid("times", "needs at least one key time");
    for (size_t k = 0; k < s.times.size(); ++k) {
      const std::string key = "times[" + std::to_string(k) + "]";
      if (s.times[k] < 0.0f) t.invalid(key, "key times must not be negative");
      if (k > 0 && !(s.times[k] > s.times[k - 1]))
        t.invalid(key, "key times must be strictly increasing (" + std::to_string(s.times[k]) +
                           " after " + std::to_string(s.times[k - 1]) + ")");
    }

    if (!t.has("values")) t.schemaError("values", "missing required key");
    const json& values = t.at("values");
    if (!values.is_array()) t.schemaError("values", "expected an array");
    const size_t perKey = cubic ? 3 : 1;
    if (values.size() != s.times.size() * perKey)
      t.invalid("values", std::to_string(values.size()) + " values for " +
                              std::to_string(s.times.size()) + " key times" +
                              (cubic ? " (cubicspline: in-tangent, value, out-tangent per key)"
                                     : std::string()) +
                              "; need " + std::to_string(s.times.size() * perKey));
    s.components = track == Track::Translation || track == Track::Scale ? 3 : 4;
    glm::vec3 previousDirection(0.0f);
    glm::quat previousRotation(1.0f, 0.0f, 0.0f, 0.0f);
    for (size_t i = 0; i < values.size(); ++i) {
      const std::string where = t.pathOf("values[" + std::to_string(i) + "]");
      const bool tangent = cubic && i % 3 != 1;
      std::vector<float> v;
      switch (track) {
        case Track::Translation:
          v = detail::numberList(values[i], where, path_, {3});
          break;
        case Track::Scale:
          v = values[i].is_number()
                  ? std::vector<float>(3, detail::numberValue(values[i], where, path_))
                  : detail::numberList(values[i], where, path_, {3});
          if (!tangent && (v[0] == 0.0f || v[1] == 0.0f || v[2] == 0.0f))
            throw Error(ErrorKind::InvalidData, path_, where + ": scale must not be zero");
          break;
        case Track::Rotation: {
          v = detail::numberList(
              values[i], where, path_,
              cubic ? std::initializer_list<size_t>{4} : std::initializer_list<size_t>{3, 4});
          if (tangent) break;  // tangents are raw quaternion derivatives
          const glm::quat q = rotationOf(v, where, path_);
          v = {q.x, q.y, q.z, q.w};
          break;
        }
        case Track::Direction: {
          const std::vector<float> d = detail::numberList(values[i], where, path_, {3});
          const glm::vec3 dir(d[0], d[1], d[2]);
          if (glm::length(dir) < 1e-6f)
            throw Error(ErrorKind::InvalidData, path_, where + ": direction must not be zero");
          // Each key turns the previous one by the shortest arc between their directions, so
          // that slerping between keys sweeps the direction along a great circle.
          const glm::vec3 now = glm::normalize(dir);
          const glm::quat q =
              i == 0 ? rotationTowards(now)
                     : glm::normalize(shortestArc(previousDirection, now) * previousRotation);
          previousDirection = now;
          previousRotation = q;
          v = {q.x, q.y, q.z, q.w};
          break;
        }
      }
      s.values.insert(s.values.end(), v.begin(), v.end());
    }
    return s;
  }

  // "orbit": the entry's whole transform turns about the line through `center` along `axis`
  // (right-handed), once per `period` seconds. As keys: 32 per turn, positions cubic with the
  // circle's tangents, rotations slerped (exact for a fixed axis); the first and last keys are
  // the entry's own transform.
  void addOrbit(const JsonObject& o, AnimationClip& clip, const TRS& rest,
                std::optional<glm::vec3> defaultCenter) const {
    o.allowOnly({"center", "axis", "period"});
    if (!o.has("center") && !defaultCenter) o.schemaError("center", "missing required key");
    const glm::vec3 center = o.has("center") ? *o.vec3("center") : *defaultCenter;
    glm::vec3 axis = o.vec3("axis").value_or(glm::vec3(0, 1, 0));
    if (glm::length(axis) < 1e-6f) o.invalid("axis", "must not be zero");
    axis = glm::normalize(axis);
    if (!o.has("period")) o.schemaError("period", "missing required key");
    const float period = *o.number("period");
    if (period <= 0.0f) o.invalid("period", "must be positive");

    constexpr int kKeys = 32;
    AnimationSampler position, rotation;
    position.interpolation = Interpolation::CubicSpline;
    position.components = 3;
    rotation.components = 4;
    const double omega = 2.0 * glm::pi<double>() / period;
    const glm::vec3 arm = rest.translation - center;
    for (int k = 0; k <= kKeys; ++k) {
      const float time = float(double(period) * k / kKeys);
      const float angle = float(2.0 * glm::pi<double>() * k / kKeys);
      const glm::quat turn = glm::angleAxis(angle, axis);
      const bool ends = k == 0 || k == kKeys;
      const glm::vec3 offset = turn * arm;
      const glm::vec3 p = ends ? rest.translation : center + offset;
      const glm::vec3 tangent = float(omega) * glm::cross(axis, offset);
      const glm::quat q = ends ? rest.rotation : glm::normalize(turn * rest.rotation);
      position.times.push_back(time);
      rotation.times.push_back(time);
      for (const glm::vec3& v : {tangent, p, tangent})
        position.values.insert(position.values.end(), {v.x, v.y, v.z});
      rotation.values.insert(rotation.values.end(), {q.x, q.y, q.z, q.w});
    }
    clip.samplers.push_back(std::move(position));
    clip.samplers.push_back(std::move(rotation));
  }

  // The entry's "animation" as a clip of its own whose channels drive `node`. Each track
  // replaces that part of the node's transform (translation keys are absolute positions);
  // parts without a track keep the entry's own value (`rest`).
  void readAnimation(const JsonObject& entry, int node, const TRS& rest, Target target,
                     std::optional<glm::vec3> orbitCenter = std::nullopt) {
    const JsonObject a(entry.at("animation"), entry.pathOf("animation"), path_);
    const bool directed = target == Target::DirectedLight;
    if (directed)
      a.allowOnly({"translation", "rotation", "scale", "direction", "orbit"});
    else
      a.allowOnly({"translation", "rotation", "scale", "orbit"});
    if (a.has("rotation") && a.has("direction"))
      a.schemaError("direction", "give either rotation or direction keys, not both");
    if (a.has("orbit"))
      for (const char* k : {"translation", "rotation", "direction"})
        if (a.has(k)) a.schemaError(k, "cannot be combined with \"orbit\"");

    AnimationClip clip;
    clip.name = scene_.nodes[node].name + " (" + a.path() + ")";
    auto track = [&](const char* key, Track kind, AnimationPath path) {
      if (!a.has(key)) return;
      clip.samplers.push_back(readTrack(JsonObject(a.at(key), a.pathOf(key), path_), kind));
      clip.channels.push_back({int(clip.samplers.size()) - 1, node, path});
    };
    track("translation", Track::Translation, AnimationPath::Translation);
    track("rotation", Track::Rotation, AnimationPath::Rotation);
    track("direction", Track::Direction, AnimationPath::Rotation);
    track("scale", Track::Scale, AnimationPath::Scale);
    if (a.has("orbit")) {
      addOrbit(JsonObject(a.at("orbit"), a.pathOf("orbit"), path_), clip, rest, orbitCenter);
      const int first = int(clip.samplers.size()) - 2;
      clip.channels.push_back({first, node, AnimationPath::Translation});
      clip.channels.push_back({first + 1, node, AnimationPath::Rotation});
    }
    if (clip.channels.empty())
      throw Error(ErrorKind::Schema, path_,
                  a.path() + ": expected at least one of translation, rotation, scale" +
                      (directed ? ", direction" : "") + " or orbit");
    for (const AnimationSampler& s : clip.samplers)
      clip.duration = std::max(clip.duration, s.times.back());

    Node& n = scene_.nodes[node];
    n.hasTRS = true;
    n.translation = rest.translation;
    n.rotation = rest.rotation;
    n.scale = rest.scale;
    n.local = rest.matrix();
    scene_.animations.push_back(std::move(clip));
  }

  Scene loadModel(const std::string& file, const JsonObject& m) {
    std::error_code ec;
    if (!fs::exists(file, ec))
      throw Error(ErrorKind::MissingResource, path_,
                  m.pathOf("file") + ": model file '" + file + "' does not exist");
    const std::string ext = detail::lowerExtension(file);
    try {
      if (ext == ".gltf" || ext == ".glb") return loadGltf(file);
      if (ext == ".obj" || ext == ".ply") return detail::loadMeshFileOnly(file);
    } catch (const Error& e) {
      // Keep the model's error (kind and file) and say which scene entry asked for it.
      std::string problem = e.what();
      if (problem.rfind(e.file() + ": ", 0) == 0) problem.erase(0, e.file().size() + 2);
      throw Error(e.kind(), e.file(), problem + " (" + m.pathOf("file") + " of " + path_ + ")");
    }
    throw Error(ErrorKind::Unsupported, path_,
                m.pathOf("file") + ": '" + file +
                    "' is not a model file (.gltf, .glb, .obj or .ply; scenes do not nest)");
  }

  void readCamera(const JsonObject& c) {
    c.allowOnly({"name", "position", "target", "up", "yfov_deg", "near", "far", "animation"});
    const glm::vec3 position = c.requireVec3("position");
    const glm::vec3 target = c.requireVec3("target");
    const glm::vec3 up = c.vec3("up").value_or(glm::vec3(0, 1, 0));
    const glm::vec3 forward = target - position;
    if (glm::length(forward) < 1e-6f) c.invalid("target", "equals the position");
    if (glm::length(glm::cross(glm::normalize(forward), up)) < 1e-4f)
      c.invalid("up", "is zero or parallel to the viewing direction");
    Camera cam;
    cam.name = c.string("name").value_or("camera");
    const float yfov = c.number("yfov_deg").value_or(45.0f);
    if (yfov <= 0.0f || yfov >= 180.0f) c.invalid("yfov_deg", "must be in (0, 180)");
    cam.yfov = glm::radians(yfov);
    cam.znear = c.number("near").value_or(cam.znear);
    cam.zfar = c.number("far").value_or(cam.zfar);
    if (cam.znear <= 0.0f) c.invalid("near", "must be positive");
    if (cam.zfar <= cam.znear) c.invalid("far", "must be greater than near");
    scene_.cameras.push_back(cam);
    const int node = scene_.addNode(cam.name, glm::inverse(glm::lookAt(position, target, up)));
    scene_.nodes[node].camera = static_cast<int>(scene_.cameras.size()) - 1;
    scene_.activeCameraNode = node;
    // An orbit about the target keeps the camera looking at it.
    if (c.has("animation")) {
      TRS rest = rigidTRS(scene_.nodes[node].local);
      rest.translation = position;  // exactly, not as the inverse look-at rounds it
      readAnimation(c, node, rest, Target::Camera, target);
    }
  }

  void readLights(const JsonObject& top) {
    const json& lights = array(top, "lights");
    for (size_t i = 0; i < lights.size(); ++i) {
      JsonObject o(lights[i], indexed("lights", i), path_);
      o.allowOnly({"type", "name", "position", "direction", "color", "intensity", "range",
                   "inner_cone_deg", "outer_cone_deg", "casts_shadows", "animation"});
      const std::string type = o.requireString("type");
      Light l;
      if (type == "point")
        l.type = LightType::Point;
      else if (type == "spot")
        l.type = LightType::Spot;
      else if (type == "directional")
        l.type = LightType::Directional;
      else
        o.schemaError("type", "unknown light type '" + type + "' (point, spot or directional)");
      l.name = o.string("name").value_or(type + " light");
      l.color = nonNegativeColor(o, "color", glm::vec3(1.0f));
      l.intensity = nonNegative(o, "intensity", 1.0f);
      l.range = nonNegative(o, "range", 0.0f);
      const float inner = o.number("inner_cone_deg").value_or(0.0f);
      const float outer = o.number("outer_cone_deg").value_or(45.0f);
      if (inner < 0.0f || inner > outer) o.invalid("inner_cone_deg", "must be in [0, outer]");
      if (outer <= 0.0f || outer > 90.0f) o.invalid("outer_cone_deg", "must be in (0, 90]");
      l.innerConeAngle = glm::radians(inner);
      l.outerConeAngle = glm::radians(outer);
      l.castsShadows = o.boolean("casts_shadows").value_or(true);

      glm::vec3 position(0.0f);
      if (l.type != LightType::Directional)
        position = o.requireVec3("position");
      else if (o.has("position"))
        position = *o.vec3("position");  // ignored by the light, kept for debugging views
      if (l.type == LightType::Point && o.has("direction"))
        o.schemaError("direction", "a point light has no direction");
      const glm::vec3 dir = o.vec3("direction").value_or(glm::vec3(0, -1, 0));
      if (glm::length(dir) < 1e-6f) o.invalid("direction", "must not be zero");
      // A light shines along its node's -z: orient the node to look along `dir`.
      const glm::vec3 d = glm::normalize(dir);
      const glm::vec3 up = std::abs(d.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
      scene_.lights.push_back(l);
      const int node =
          scene_.addNode(l.name, glm::inverse(glm::lookAt(position, position + d, up)));
      scene_.nodes[node].light = static_cast<int>(scene_.lights.size()) - 1;
      if (o.has("animation")) {
        TRS rest = rigidTRS(scene_.nodes[node].local);
        rest.translation = position;
        readAnimation(o, node, rest,
                      l.type == LightType::Point ? Target::Light : Target::DirectedLight);
      }
    }
  }

  void readEnvironment(const JsonObject& e) {
    e.allowOnly(
        {"type", "intensity", "color", "zenith_color", "horizon_color", "ground_color", "file"});
    Environment& env = scene_.environment;
    const std::string type = e.string("type").value_or("sky");
    if (type == "sky") {
      env.kind = Environment::Kind::Sky;
      if (e.has("color")) e.schemaError("color", "only for \"type\": \"constant\"");
      env.zenithColor = nonNegativeColor(e, "zenith_color", env.zenithColor);
      env.horizonColor = nonNegativeColor(e, "horizon_color", env.horizonColor);
      env.groundColor = nonNegativeColor(e, "ground_color", env.groundColor);
    } else if (type == "constant") {
      env.kind = Environment::Kind::Constant;
      for (const char* k : {"zenith_color", "horizon_color", "ground_color"})
        if (e.has(k)) e.schemaError(k, "only for \"type\": \"sky\"");
      env.constantColor = nonNegativeColor(e, "color", env.constantColor);
    } else if (type == "map") {
      for (const char* k : {"color", "zenith_color", "horizon_color", "ground_color"})
        if (e.has(k)) e.schemaError(k, "not for \"type\": \"map\"");
      const std::string file = e.requireString("file");
      const fs::path resolved = expandModelPath(file, fs::path(path_).parent_path(), e);
      std::error_code ec;
      if (!fs::exists(resolved, ec))
        throw Error(
            ErrorKind::MissingResource, path_,
            e.pathOf("file") + ": environment map '" + resolved.string() + "' does not exist");
      if (detail::lowerExtension(resolved.string()) != ".hdr")
        e.schemaError("file", "'" + file + "' is not a Radiance .hdr file");
      loadEnvironmentMap(env, resolved.string());
    } else {
      e.schemaError("type", "unknown environment type '" + type + "' (sky, constant or map)");
    }
    if (type != "map" && e.has("file")) e.schemaError("file", "only for \"type\": \"map\"");
    env.intensity = nonNegative(e, "intensity", env.intensity);
  }

  void readEffects(const JsonObject& top) {
    const json& effects = array(top, "effects");
    for (size_t i = 0; i < effects.size(); ++i) {
      EffectRequest request;
      if (effects[i].is_string()) {
        request.name = effects[i].get<std::string>();
      } else {
        JsonObject o(effects[i], indexed("effects", i), path_);
        o.allowOnly({"name", "settings"});
        request.name = o.requireString("name");
        if (o.has("settings")) {
          if (!o.at("settings").is_object()) o.schemaError("settings", "expected an object");
          request.settings = o.at("settings");
        }
      }
      if (request.name.empty())
        throw Error(ErrorKind::Schema, path_, indexed("effects", i) + ": empty effect name");
      scene_.effects.push_back(std::move(request));
    }
  }

  void readRegions(const JsonObject& top) {
    const json& regions = array(top, "regions");
    scene_.regions.clear();  // an included default scene's regions are replaced
    for (size_t i = 0; i < regions.size(); ++i) {
      JsonObject o(regions[i], indexed("regions", i), path_);
      o.allowOnly({"name", "min", "max"});
      SceneRegion r;
      r.name = o.requireString("name");
      const std::optional<glm::vec3> lo = o.vec3("min"), hi = o.vec3("max");
      if (!lo) o.schemaError("min", "required: [x, y, z]");
      if (!hi) o.schemaError("max", "required: [x, y, z]");
      r.min = *lo;
      r.max = *hi;
      if (r.name.empty()) o.invalid("name", "must not be empty");
      if (!(r.min.x <= r.max.x && r.min.y <= r.max.y && r.min.z <= r.max.z))
        o.invalid("max", "must be at least min in every component");
      for (const SceneRegion& other : scene_.regions)
        if (other.name == r.name) o.invalid("name", "'" + r.name + "' is used twice");
      scene_.regions.push_back(r);
    }
  }

  const std::string& path_;
  Scene scene_;
};

}  // namespace

Scene loadSceneJson(const std::string& path) {
  return SceneJsonLoader(path).load();
}

namespace {

// A scene whose geometry collapses to a point (a node scale of 0) or to nothing finite renders
// only sky: refused. One far outside the sizes the renderer's fixed epsilons suit is warned of.
void checkSceneSize(Scene& s, const std::string& path) {
  glm::vec3 lo, hi;
  s.worldBounds(lo, hi);
  const float diagonal = glm::length(hi - lo);
  std::ostringstream b;
  b << "bounds [" << lo.x << ", " << lo.y << ", " << lo.z << "] .. [" << hi.x << ", " << hi.y
    << ", " << hi.z << "]";
  const std::string bounds = b.str();
  if (!std::isfinite(diagonal))
    throw Error(ErrorKind::NonFinite, path,
                "the scene's size is not finite (" + bounds +
                    "): a transform overflows; nothing could be rendered");
  if (diagonal == 0.0f)
    throw Error(ErrorKind::InvalidData, path,
                "the scene's geometry has zero size (" + bounds +
                    "; a node scale of 0?): nothing would be visible");
  std::ostringstream size;
  size << diagonal;
  if (diagonal < 1e-4f || diagonal > 1e7f)
    s.warnings.push_back(path + ": the scene is " + size.str() +
                         " units across; sizes far from 1 lose depth and shadow precision");
}

// The file, by its extension (the dispatch of loadScene).
Scene loadSceneFile(const std::string& pathOrDefault) {
  std::error_code ec;
  if (!fs::exists(pathOrDefault, ec))
    throw Error(ErrorKind::FileNotFound, pathOrDefault, "file does not exist");
  const std::string ext = detail::lowerExtension(pathOrDefault);
  if (ext == ".json") return loadSceneJson(pathOrDefault);
  if (ext == ".obj" || ext == ".ply" || ext == ".gltf" || ext == ".glb") {
    Scene s =
        ext == ".obj" || ext == ".ply" ? loadMeshFile(pathOrDefault) : loadGltf(pathOrDefault);
    addDefaultCameraAndLight(s);  // a bare model file: framed, lit, effects sized to it
    glm::vec3 lo, hi;
    s.worldBounds(lo, hi);
    const float diagonal = glm::length(hi - lo);
    // Guard: an empty, degenerate or non-finite model keeps the defaults as they are.
    if (std::isfinite(diagonal) && diagonal > 0.0f)
      s.lengthScale = diagonal / kReferenceSceneDiagonal;
    return s;
  }
  throw Error(ErrorKind::Unsupported, pathOrDefault,
              "unsupported scene format '" + ext +
                  "' (.json, .gltf, .glb, .obj, .ply or "
                  "\"default\")");
}

}  // namespace

Scene loadScene(const std::string& pathOrDefault) {
  if (pathOrDefault == "default") return makeDefaultScene();
  Scene s = loadSceneFile(pathOrDefault);
  checkSceneSize(s, pathOrDefault);
  return s;
}

}  // namespace gi
