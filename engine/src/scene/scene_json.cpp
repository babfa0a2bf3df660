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
//                                          // or starting with ${GI_SHARED_ASSETS} /
//                                          ${ASSIMP_MODELS}
//       "name": "engine",
//       "translation": [0, 0, 0],
//       "rotation": [0, 0, 0, 1],          // quaternion [x, y, z, w], or Euler degrees [x, y, z]
//                                          // applied about X, then Y, then Z (fixed axes)
//       "scale": 1.0 },                    // or [sx, sy, sz]; no zero components
//     { "primitive": "plane" | "box" | "sphere",   // instead of "file"
//       "size": 4.0,                       // plane: number or [x, z]; box: number or [x, y, z]
//       "radius": 0.5, "segments": 32, "rings": 16,  // sphere only
//       "material": { "name": "...", "base_color": [r, g, b(, a)], "emission": [r, g, b],
//                     "roughness": 0.8, "metallic": 0.0 },
//       "name", "translation", "rotation", "scale" as above }
//   ],
//   "camera": { "position": [x, y, z] (required), "target": [x, y, z] (required),
//               "up": [0, 1, 0], "yfov_deg": 45, "near": 0.05, "far": 1000, "name": "..." },
//   "lights": [ { "type": "point" | "spot" | "directional" (required), "name": "...",
//                 "position": [x, y, z] (required for point and spot),
//                 "direction": [0, -1, 0] (spot and directional: where the light travels),
//                 "color": [1, 1, 1], "intensity": 1 (candela; lux for directional),
//                 "range": 0 (0: infinite), "inner_cone_deg": 0, "outer_cone_deg": 45,
//                 "casts_shadows": true } ],
//   "environment": { "type": "sky" | "constant" | "map", "intensity": 1,
//                    "color": [r, g, b] (constant only),
//                    "file": "sky.hdr" (map only, required: equirectangular Radiance .hdr,
//                            relative to the scene file; ${GI_SHARED_ASSETS} expands),
//                    "zenith_color", "horizon_color", "ground_color": [r, g, b] (sky only) },
//   "effects": [ "ssao", { "name": "bloom", "settings": { ... } } ]
// }
//
// ${GI_SHARED_ASSETS} expands to the environment variable of that name when set, else to the
// nearest "shared/assets" folder found walking up from the scene file's folder (the checkout's
// ../shared/assets). ${ASSIMP_MODELS} expands to $ASSIMP_MODELS, else /usr/share/assimp/models.
//
// Without a "camera" (and no camera in the models) the scene is framed automatically; without
// any light a sun is added (addDefaultCameraAndLight). The JSON camera becomes the active one.
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "gi/environment.h"
#include "gi/errors.h"
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

// Expands a leading ${GI_SHARED_ASSETS} / ${ASSIMP_MODELS}; other ${...} are errors.
fs::path expandModelPath(const std::string& file, const fs::path& sceneDir, const JsonObject& o,
                         const std::string& scenePath) {
  if (file.rfind("${", 0) != 0) {
    fs::path p(file);
    return p.is_absolute() ? p : sceneDir / p;
  }
  const size_t close = file.find('}');
  if (close == std::string::npos) o.schemaError("file", "unterminated '${' in '" + file + "'");
  const std::string var = file.substr(2, close - 2);
  std::string rest = file.substr(close + 1);
  while (!rest.empty() && (rest.front() == '/' || rest.front() == '\\')) rest.erase(0, 1);
  if (const char* env = std::getenv(var.c_str());
      env && *env && (var == "GI_SHARED_ASSETS" || var == "ASSIMP_MODELS"))
    return fs::path(env) / rest;
  if (var == "ASSIMP_MODELS") return fs::path("/usr/share/assimp/models") / rest;
  if (var == "GI_SHARED_ASSETS") {
    std::error_code ec;
    const fs::path start = fs::weakly_canonical(sceneDir.empty() ? fs::path(".") : sceneDir, ec);
    for (fs::path dir = start; !dir.empty(); dir = dir.parent_path()) {
      if (fs::is_directory(dir / "shared" / "assets", ec)) return dir / "shared" / "assets" / rest;
      if (dir == dir.parent_path()) break;
    }
    throw Error(ErrorKind::MissingResource, scenePath,
                o.pathOf("file") + ": '" + file +
                    "': no shared/assets folder above the scene file and GI_SHARED_ASSETS is "
                    "not set");
  }
  o.schemaError("file",
                "unknown variable '${" + var + "}' (known: ${GI_SHARED_ASSETS}, ${ASSIMP_MODELS})");
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
  o.allowOnly({"name", "base_color", "emission", "roughness", "metallic"});
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
  if (m.roughness < 0 || m.roughness > 1) o.invalid("roughness", "must be in [0, 1]");
  if (m.metallic < 0 || m.metallic > 1) o.invalid("metallic", "must be in [0, 1]");
  return m;
}

// A "primitive" model as a one-mesh scene (`file`: the scene file, for messages).
Scene makePrimitive(const JsonObject& o, const std::string& file) {
  const std::string kind = o.requireString("primitive");
  Mesh mesh;
  if (kind == "plane" || kind == "box") {
    o.allowOnly({"primitive", "name", "translation", "rotation", "scale", "size", "material"});
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
    mesh = kind == "plane" ? detail::makePlane(size.x, size.z) : detail::makeBox(size);
  } else if (kind == "sphere") {
    o.allowOnly({"primitive", "name", "translation", "rotation", "scale", "radius", "segments",
                 "rings", "material"});
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
    json root;
    try {
      root = json::parse(text, nullptr, true, /*ignore_comments=*/true);
    } catch (const json::parse_error& e) {
      // nlohmann's message carries "line L, column C".
      throw Error(ErrorKind::Parse, path_, std::string("invalid JSON: ") + e.what());
    }
    JsonObject top(root, "", path_);
    top.allowOnly({"description", "include_default_scene", "models", "camera", "lights",
                   "environment", "effects"});
    top.string("description");  // type check only
    if (top.boolean("include_default_scene").value_or(false)) scene_ = makeDefaultScene();
    scene_.sourcePath = path_;

    if (top.has("models")) readModels(top);
    if (top.has("camera")) readCamera(JsonObject(top.at("camera"), "camera", path_));
    if (top.has("lights")) readLights(top);
    if (top.has("environment"))
      readEnvironment(JsonObject(top.at("environment"), "environment", path_));
    if (top.has("effects")) readEffects(top);

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
        m.allowOnly({"file", "name", "translation", "rotation", "scale"});
        const std::string file = m.requireString("file");
        const fs::path resolved = expandModelPath(file, sceneDir, m, path_);
        model = loadModel(resolved.string(), m);
        name = m.string("name").value_or(resolved.stem().string());
      }
      detail::mergeScene(scene_, std::move(model), name, readTransform(m));
    }
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
    c.allowOnly({"name", "position", "target", "up", "yfov_deg", "near", "far"});
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
  }

  void readLights(const JsonObject& top) {
    const json& lights = array(top, "lights");
    for (size_t i = 0; i < lights.size(); ++i) {
      JsonObject o(lights[i], indexed("lights", i), path_);
      o.allowOnly({"type", "name", "position", "direction", "color", "intensity", "range",
                   "inner_cone_deg", "outer_cone_deg", "casts_shadows"});
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
      const fs::path resolved = expandModelPath(file, fs::path(path_).parent_path(), e, path_);
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

  const std::string& path_;
  Scene scene_;
};

}  // namespace

Scene loadSceneJson(const std::string& path) {
  return SceneJsonLoader(path).load();
}

Scene loadScene(const std::string& pathOrDefault) {
  if (pathOrDefault == "default") return makeDefaultScene();
  std::error_code ec;
  if (!fs::exists(pathOrDefault, ec))
    throw Error(ErrorKind::FileNotFound, pathOrDefault, "file does not exist");
  const std::string ext = detail::lowerExtension(pathOrDefault);
  if (ext == ".json") return loadSceneJson(pathOrDefault);
  if (ext == ".obj" || ext == ".ply") return loadMeshFile(pathOrDefault);
  if (ext == ".gltf" || ext == ".glb") {
    Scene s = loadGltf(pathOrDefault);
    addDefaultCameraAndLight(s);  // a bare model file, like .obj/.ply
    return s;
  }
  throw Error(ErrorKind::Unsupported, pathOrDefault,
              "unsupported scene format '" + ext +
                  "' (.json, .gltf, .glb, .obj, .ply or "
                  "\"default\")");
}

}  // namespace gi
