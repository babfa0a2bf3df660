#include "gi/scene_hash.h"

#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace gi {

namespace {

// FNV-1a over bytes; fields are fed one by one (never whole structs, whose padding is
// indeterminate).
class Hasher {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 1099511628211ULL;
  }
  template <class T>
  void operator()(const T& v) {
    static_assert(std::has_unique_object_representations_v<T> || std::is_floating_point_v<T>);
    bytes(&v, sizeof v);
  }
  void operator()(bool v) { (*this)(uint8_t(v)); }
  void operator()(const std::string& s) {
    (*this)(uint64_t(s.size()));
    bytes(s.data(), s.size());
  }
  void operator()(const glm::vec2& v) { floats(&v.x, 2); }
  void operator()(const glm::vec3& v) { floats(&v.x, 3); }
  void operator()(const glm::vec4& v) { floats(&v.x, 4); }
  void operator()(const glm::quat& v) { floats(&v.x, 4); }
  void operator()(const glm::mat4& m) { floats(&m[0][0], 16); }
  void operator()(const glm::uvec4& v) { bytes(&v.x, sizeof(uint32_t) * 4); }
  template <class T>
  void operator()(const std::vector<T>& v) {
    (*this)(uint64_t(v.size()));
    if constexpr (std::is_arithmetic_v<T>)
      bytes(v.data(), v.size() * sizeof(T));
    else
      for (const T& x : v) (*this)(x);
  }
  uint64_t value() const { return h_; }

 private:
  void floats(const float* f, size_t n) { bytes(f, n * sizeof(float)); }
  uint64_t h_ = 1469598103934665603ULL;
};

}  // namespace

uint64_t sceneContentHash(const Scene& scene) {
  Hasher h;
  h(uint64_t(scene.meshes.size()));
  for (const Mesh& m : scene.meshes) {
    h(uint64_t(m.vertices.size()));
    for (const Vertex& v : m.vertices) {
      h(v.position);
      h(v.normal);
      h(v.uv);
    }
    h(m.indices);
    h(m.material);
    h(m.joints);
    h(m.weights);
    for (const MorphTarget& t : m.morphTargets) {
      h(t.positionDeltas);
      h(t.normalDeltas);
    }
    h(m.morphWeights);
  }
  h(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    h(m.baseColor);
    h(m.baseColorTexture);
    h(m.emission);
    h(m.roughness);
    h(m.metallic);
    h(m.doubleSided);
  }
  h(uint64_t(scene.textures.size()));
  for (const Texture& t : scene.textures) {
    h(t.width);
    h(t.height);
    h(t.rgba8);
  }
  h(uint64_t(scene.cameras.size()));
  for (const Camera& c : scene.cameras) {
    h(c.yfov);
    h(c.aspect);
    h(c.znear);
    h(c.zfar);
  }
  h(uint64_t(scene.lights.size()));
  for (const Light& l : scene.lights) {
    h(int(l.type));
    h(l.color);
    h(l.intensity);
    h(l.range);
    h(l.innerConeAngle);
    h(l.outerConeAngle);
    h(l.castsShadows);
    h(l.shadowBias.constant);
    h(l.shadowBias.slope);
  }
  h(uint64_t(scene.nodes.size()));
  for (const Node& n : scene.nodes) {
    h(n.parent);
    h(n.local);
    h(n.world);
    h(n.meshes);
    h(n.camera);
    h(n.light);
    h(n.skin);
    h(n.morphWeights);
  }
  h(scene.activeCameraNode);
  for (const Skin& s : scene.skins) {
    h(s.joints);
    h(s.inverseBindMatrices);
  }
  for (const AnimationClip& a : scene.animations) {
    for (const AnimationSampler& s : a.samplers) {
      h(s.times);
      h(s.values);
      h(int(s.interpolation));
      h(s.components);
    }
    for (const AnimationChannel& c : a.channels) {
      h(c.sampler);
      h(c.node);
      h(int(c.path));
    }
  }
  const Environment& e = scene.environment;
  h(int(e.kind));
  h(e.zenithColor);
  h(e.horizonColor);
  h(e.groundColor);
  h(e.constantColor);
  h(e.intensity);
  h(e.mapWidth);
  h(e.mapHeight);
  h(e.mapRGB);
  h(scene.lengthScale);
  return h.value();
}

}  // namespace gi
