// Scene data shared by every loader, the Vulkan renderer and (later) the reference renderer.
// Plain data, no Vulkan: loaders fill it, Scene::updateWorldTransforms() derives world state.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

namespace gi {

struct Vertex {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  glm::vec2 uv{0.0f};
};

// Per-target vertex deltas of a morph target (glTF targets: POSITION and NORMAL), parallel to
// Mesh::vertices; normalDeltas may be empty.
struct MorphTarget {
  std::vector<glm::vec3> positionDeltas;
  std::vector<glm::vec3> normalDeltas;
};

// One triangle list with one material (a glTF primitive, an OBJ material group).
struct Mesh {
  std::string name;
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;  // triangle list, always 32-bit after loading
  uint32_t material = 0;
  std::vector<float> triangleAreas;  // object-space area per triangle (mesh_processing)
  glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
  size_t triangleCount() const { return indices.size() / 3; }

  // Skinning (glTF JOINTS_0 / WEIGHTS_0), parallel to vertices or empty for rigid meshes.
  // Joint indices refer to the joints of the Skin of the node drawing the mesh. Weights are
  // renormalised to sum 1 by the loader; an all-zero row keeps the vertex in its bind pose.
  std::vector<glm::uvec4> joints;
  std::vector<glm::vec4> weights;
  bool skinned() const { return !joints.empty() && joints.size() == vertices.size(); }
  // Morph targets (applied on the CPU, see gi/animation.h) and their default weights.
  std::vector<MorphTarget> morphTargets;
  std::vector<float> morphWeights;
};

struct Texture {
  std::string name;
  int width = 0, height = 0;
  std::vector<uint8_t> rgba8;  // width*height*4, sRGB-encoded colour
};

// The size effects' world-length defaults are chosen for: the bounding-box diagonal of the
// built-in room (2 units across). Scene::lengthScale compares a bare model with it.
inline constexpr float kReferenceSceneDiagonal = 3.4641016f;  // 2 sqrt(3)

struct Material {
  std::string name;
  glm::vec4 baseColor{0.8f, 0.8f, 0.8f, 1.0f};  // linear
  int baseColorTexture = -1;                    // index into Scene::textures
  glm::vec3 emission{0.0f};                     // linear radiance added on top of lighting
  float roughness = 0.8f;
  float metallic = 0.0f;
  // Emission leaves the side the surface's normal points to; double-sided (glTF doubleSided):
  // both sides. Only emission is one-sided: every surface reflects light on both sides (the
  // rasteriser culls no faces).
  bool doubleSided = false;
};

struct Camera {
  std::string name;
  float yfov = glm::radians(45.0f);  // radians
  float aspect = 0.0f;               // as stored in the file; rendering uses the output's
  float znear = 0.05f;
  float zfar = 1000.0f;
};

enum class LightType { Directional, Point, Spot };

struct Light {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;  // glTF units: lux (directional) or candela (point/spot)
  float range = 0.0f;      // 0: infinite
  float innerConeAngle = 0.0f;
  float outerConeAngle = glm::radians(45.0f);
  bool castsShadows = true;
  // Shadow-map depth bias, in shadow-map texels of world-space depth at the receiver: the
  // compared depth is pushed towards the light by texel * (constant + slope * tan(angle between
  // normal and light)), tan clamped to 10. The defaults keep a lit plane free of acne with the
  // 3x3 PCF of lighting.comp; SSDO and other consumers read the same values.
  struct ShadowBias {
    float constant = 1.0f;
    float slope = 2.0f;
  } shadowBias;
};

struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  // Local transform as translation, rotation, scale (what animations set). When `hasTRS`,
  // `local` is T * R * S; nodes given by a matrix keep hasTRS false and are not animated.
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  bool hasTRS = false;
  glm::mat4 local{1.0f};
  glm::mat4 world{1.0f};            // derived by Scene::updateWorldTransforms()
  std::vector<int> meshes;          // indices into Scene::meshes
  int camera = -1;                  // index into Scene::cameras
  int light = -1;                   // index into Scene::lights
  int skin = -1;                    // index into Scene::skins (the node's meshes are skinned by it)
  std::vector<float> morphWeights;  // current morph weights of the node's meshes (may be empty)
};

// A glTF skin: joint nodes and their inverse bind matrices (identity when the file has none).
struct Skin {
  std::string name;
  std::vector<int> joints;  // scene node indices
  std::vector<glm::mat4> inverseBindMatrices;
};

enum class Interpolation { Linear, Step, CubicSpline };
enum class AnimationPath { Translation, Rotation, Scale, Weights };

// Keyframes: `times` strictly increasing; `values` has `components` floats per key, times 3
// for CUBICSPLINE (in-tangent, value, out-tangent per key, as glTF stores them). Rotations are
// quaternions stored x, y, z, w.
struct AnimationSampler {
  std::vector<float> times;
  std::vector<float> values;
  Interpolation interpolation = Interpolation::Linear;
  int components = 1;
};

struct AnimationChannel {
  int sampler = 0;  // index into AnimationClip::samplers
  int node = 0;     // scene node index
  AnimationPath path = AnimationPath::Translation;
};

struct AnimationClip {
  std::string name;
  std::vector<AnimationSampler> samplers;
  std::vector<AnimationChannel> channels;
  float duration = 0.0f;  // last key time over all samplers; the clip loops with this period
};

// Procedural sky (default) lights the scene's ambient term and the background. Kind::Map is an
// equirectangular HDR image (gi/environment.h: lookup, importance sampling, SH9 irradiance).
struct Environment {
  enum class Kind { Sky, Constant, Map } kind = Kind::Sky;
  glm::vec3 zenithColor{0.25f, 0.45f, 0.85f};
  glm::vec3 horizonColor{0.85f, 0.9f, 1.0f};
  glm::vec3 groundColor{0.3f, 0.27f, 0.25f};
  glm::vec3 constantColor{1.0f};
  float intensity = 1.0f;
  // Kind::Map: linear RGB texels, row 0 looking up (+y); the direction mapping is
  // gi::equirectDirection in gi/environment.h. `file` is the path as resolved by the loader.
  std::string file;
  int mapWidth = 0, mapHeight = 0;
  std::vector<float> mapRGB;  // mapWidth * mapHeight * 3
};

// An effect the scene asks for, with optional setting overrides (given meaning by the effect
// registry; the scene only carries them).
struct EffectRequest {
  std::string name;
  nlohmann::json settings = nlohmann::json::object();
};

// A named part of the scene for per-region scores (gi-bench): the surface points inside an
// axis-aligned world-space box (e.g. the floor, a wall, the strip where an object meets the
// floor).
struct SceneRegion {
  std::string name;
  glm::vec3 min{0.0f}, max{0.0f};
  bool contains(const glm::vec3& p) const {
    return p.x >= min.x && p.y >= min.y && p.z >= min.z && p.x <= max.x && p.y <= max.y &&
           p.z <= max.z;
  }
};

struct Scene {
  std::string sourcePath;  // file it came from ("default" for the built-in scene)
  std::vector<Mesh> meshes;
  std::vector<Material> materials;  // never empty after loading (a default material is added)
  std::vector<Texture> textures;
  std::vector<Camera> cameras;
  std::vector<Light> lights;
  std::vector<Node> nodes;
  std::vector<int> roots;  // top-level nodes
  std::vector<Skin> skins;
  std::vector<AnimationClip> animations;
  int activeCameraNode = -1;  // node carrying the camera used for rendering, -1: frame bounds
  Environment environment;
  std::vector<EffectRequest> effects;
  std::vector<SceneRegion> regions;   // for per-region scores; none: the image as a whole
  std::vector<std::string> warnings;  // things sanitised while loading (e.g. recomputed normals)
  // Multiplies the defaults of effects' world-length settings (SettingDesc::worldLength): 1 for
  // scene files and the built-in room; a model loaded without a scene file gets its bounding-box
  // diagonal / kReferenceSceneDiagonal.
  float lengthScale = 1.0f;

  // Recompute Node::world from Node::local down the hierarchy.
  void updateWorldTransforms();
  // Samples the animation clips at `time` seconds (each clip looping over its duration;
  // clip -1: all clips, else only that one), sets the animated nodes' TRS / morph weights,
  // then updates local and world transforms. Deterministic: depends only on time and clip.
  void animate(double time, int clip = -1);
  // World-space bounds of all mesh instances (after updateWorldTransforms).
  void worldBounds(glm::vec3& outMin, glm::vec3& outMax) const;
  size_t triangleCount() const;  // sum over meshes (each mesh counted once)
  // Add a node at the root with the given transform; returns its index.
  int addNode(const std::string& name, const glm::mat4& local, int parent = -1);
};

// A camera ready for rendering: view and projection matrices (reverse-Z), derived from a node
// or by framing the scene bounds.
struct CameraView {
  glm::mat4 view{1.0f};
  glm::mat4 proj{1.0f};  // reverse-Z: depth 1 at znear, 0 at zfar
  glm::vec3 position{0.0f};
  float znear = 0.05f, zfar = 1000.0f, yfov = glm::radians(45.0f);
};

// Reverse-Z perspective projection (Vulkan clip space, depth 1 at near, 0 at far).
glm::mat4 perspectiveReverseZ(float yfov, float aspect, float znear, float zfar);
// Reverse-Z orthographic projection (Vulkan clip space): depth 1 at znear, 0 at zfar.
glm::mat4 orthoReverseZ(float left, float right, float bottom, float top, float znear, float zfar);
// Guard: `v` normalised, or `fallback` when it is zero or not finite.
glm::vec3 safeNormalize(const glm::vec3& v, const glm::vec3& fallback);
// The view looking from `eye` along the unit `forward`, +y up (+z when forward is nearly
// vertical): the convention of shadow views and GpuScene's views.
glm::mat4 lookAlong(const glm::vec3& eye, const glm::vec3& forward);
CameraView cameraFromNode(const Scene& scene, int node, float aspect);
CameraView cameraFramingBounds(const glm::vec3& bmin, const glm::vec3& bmax, float aspect);
CameraView activeCamera(const Scene& scene, float aspect);

}  // namespace gi
