// Animation sampling (LINEAR / STEP / CUBICSPLINE, short-arc slerp, looping, clip selection),
// the loader's animation, skin and morph-target data and its validation, and the CPU
// reference skinning. CPU only.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "gi/animation.h"
#include "gi/errors.h"
#include "gi/scene_io.h"
#include "test_support.h"

namespace gi {
namespace {

using nlohmann::json;

AnimationSampler makeSampler(Interpolation interp, std::vector<float> times,
                             std::vector<float> values, int components) {
  AnimationSampler s;
  s.interpolation = interp;
  s.times = std::move(times);
  s.values = std::move(values);
  s.components = components;
  return s;
}

glm::quat asQuat(const std::vector<float>& v) {
  return glm::quat(v[3], v[0], v[1], v[2]);
}

// Same rotation: q and -q are equal.
void expectSameRotation(const glm::quat& a, const glm::quat& b, float eps = 1e-5f) {
  EXPECT_NEAR(std::abs(glm::dot(a, b)), 1.0f, eps)
      << "(" << a.w << "," << a.x << "," << a.y << "," << a.z << ") vs (" << b.w << "," << b.x
      << "," << b.y << "," << b.z << ")";
}

TEST(AnimationSampling, LinearInterpolatesAndClamps) {
  AnimationSampler s =
      makeSampler(Interpolation::Linear, {0.0f, 1.0f, 2.0f}, {0, 0, 0, 2, 0, 0, 2, 4, 0}, 3);
  auto v = sampleAnimation(s, 0.5);
  EXPECT_FLOAT_EQ(v[0], 1.0f);
  EXPECT_FLOAT_EQ(v[1], 0.0f);
  v = sampleAnimation(s, 1.5);
  EXPECT_FLOAT_EQ(v[0], 2.0f);
  EXPECT_FLOAT_EQ(v[1], 2.0f);
  v = sampleAnimation(s, -1.0);  // before the first key: first value
  EXPECT_FLOAT_EQ(v[0], 0.0f);
  v = sampleAnimation(s, 7.0);  // after the last: last value
  EXPECT_FLOAT_EQ(v[1], 4.0f);
}

TEST(AnimationSampling, StepHoldsUntilTheNextKey) {
  AnimationSampler s = makeSampler(Interpolation::Step, {0.0f, 1.0f, 2.0f}, {1, 5, 9}, 1);
  EXPECT_FLOAT_EQ(sampleAnimation(s, 0.0)[0], 1.0f);
  EXPECT_FLOAT_EQ(sampleAnimation(s, 0.999)[0], 1.0f);
  EXPECT_FLOAT_EQ(sampleAnimation(s, 1.0)[0], 5.0f);
  EXPECT_FLOAT_EQ(sampleAnimation(s, 1.7)[0], 5.0f);
  EXPECT_FLOAT_EQ(sampleAnimation(s, 2.5)[0], 9.0f);
}

TEST(AnimationSampling, CubicSplineUsesTangentsScaledByKeyInterval) {
  // Keys at 0 and 2; per key: in-tangent, value, out-tangent.
  AnimationSampler s =
      makeSampler(Interpolation::CubicSpline, {0.0f, 2.0f}, {7, 1, 3, -1, 5, 11}, 1);
  // u = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875, dt = 2:
  // 0.84375*1 + 0.140625*2*3 + 0.15625*5 + (-0.046875)*2*(-1) = 2.5625
  EXPECT_NEAR(sampleAnimation(s, 0.5)[0], 2.5625f, 1e-6f);
  EXPECT_NEAR(sampleAnimation(s, 0.0)[0], 1.0f, 1e-6f);  // values, not tangents, at keys
  EXPECT_NEAR(sampleAnimation(s, 2.0)[0], 5.0f, 1e-6f);
  EXPECT_NEAR(sampleAnimation(s, 9.0)[0], 5.0f, 1e-6f);
  // u = 0.5: 0.5*1 + 0.125*2*3 + 0.5*5 + (-0.125)*2*(-1) = 4
  EXPECT_NEAR(sampleAnimation(s, 1.0)[0], 4.0f, 1e-6f);
}

TEST(AnimationSampling, CubicSplineRotationIsNormalised) {
  const glm::quat a = glm::angleAxis(0.0f, glm::vec3(0, 0, 1));
  const glm::quat b = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
  AnimationSampler s = makeSampler(
      Interpolation::CubicSpline, {0.0f, 1.0f},
      {0, 0, 0, 0, a.x, a.y, a.z, a.w, 0, 0, 0, 0, 0, 0, 0, 0, b.x, b.y, b.z, b.w, 0, 0, 0, 0}, 4);
  const glm::quat q = asQuat(sampleAnimation(s, 0.5, true));
  EXPECT_NEAR(glm::length(q), 1.0f, 1e-6f);
  // Zero tangents: h00 = h01 = 0.5 -> normalize(a + b) = the 45 degree rotation.
  expectSameRotation(q, glm::angleAxis(glm::radians(45.0f), glm::vec3(0, 0, 1)));
}

TEST(AnimationSampling, SlerpTakesTheShortArc) {
  const glm::vec3 z(0, 0, 1);
  const glm::quat a(1, 0, 0, 0);
  const glm::quat b = glm::angleAxis(glm::radians(90.0f), z);
  auto sampler = [&](const glm::quat& q1) {
    return makeSampler(Interpolation::Linear, {0.0f, 1.0f},
                       {a.x, a.y, a.z, a.w, q1.x, q1.y, q1.z, q1.w}, 4);
  };
  const glm::quat half = glm::angleAxis(glm::radians(45.0f), z);
  expectSameRotation(asQuat(sampleAnimation(sampler(b), 0.5, true)), half);
  // -b is the same rotation: still the 45 degree midpoint, not the long way round.
  expectSameRotation(asQuat(sampleAnimation(sampler(-b), 0.5, true)), half);
  // 270 degrees about z is -90 degrees: the short arc passes through -45.
  const glm::quat c = glm::angleAxis(glm::radians(270.0f), z);
  expectSameRotation(asQuat(sampleAnimation(sampler(c), 0.5, true)),
                     glm::angleAxis(glm::radians(-45.0f), z));
  // A quarter of the way: 22.5 degrees.
  expectSameRotation(asQuat(sampleAnimation(sampler(-b), 0.25, true)),
                     glm::angleAxis(glm::radians(22.5f), z));
}

// Two nodes, clip 0 moves node 0 along x over 2 s, clip 1 rotates node 1 over 4 s.
Scene twoClipScene() {
  Scene s;
  s.addNode("a", glm::mat4(1.0f));
  s.addNode("b", glm::mat4(1.0f));
  for (Node& n : s.nodes) n.hasTRS = true;
  AnimationClip move;
  move.name = "move";
  move.samplers.push_back(makeSampler(Interpolation::Linear, {0.0f, 2.0f}, {0, 0, 0, 4, 0, 0}, 3));
  move.channels.push_back({0, 0, AnimationPath::Translation});
  move.duration = 2.0f;
  AnimationClip spin;
  spin.name = "spin";
  const glm::quat q = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));
  spin.samplers.push_back(
      makeSampler(Interpolation::Linear, {0.0f, 4.0f}, {0, 0, 0, 1, q.x, q.y, q.z, q.w}, 4));
  spin.channels.push_back({0, 1, AnimationPath::Rotation});
  spin.duration = 4.0f;
  s.animations = {move, spin};
  return s;
}

TEST(AnimationScene, LoopsOverTheClipDuration) {
  EXPECT_DOUBLE_EQ(loopTime(2.5, 2.0), 0.5);
  EXPECT_DOUBLE_EQ(loopTime(-0.5, 2.0), 1.5);
  EXPECT_DOUBLE_EQ(loopTime(3.0, 0.0), 0.0);
  Scene s = twoClipScene();
  s.animate(0.5);
  EXPECT_NEAR(s.nodes[0].world[3].x, 1.0f, 1e-6f);
  const glm::mat4 rotationAtHalf = s.nodes[1].world;
  s.animate(2.5);  // clip 0 wrapped (0.5 again); clip 1 at 2.5 of 4
  EXPECT_NEAR(s.nodes[0].world[3].x, 1.0f, 1e-6f);
  s.animate(4.5);  // both wrapped to 0.5
  EXPECT_NEAR(s.nodes[0].world[3].x, 1.0f, 1e-6f);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(s.nodes[1].world[c][r], rotationAtHalf[c][r], 1e-5f);
}

TEST(AnimationScene, SelectsOneClip) {
  Scene s = twoClipScene();
  s.animate(1.0, 1);  // only "spin"
  EXPECT_NEAR(s.nodes[0].world[3].x, 0.0f, 1e-6f);
  expectSameRotation(s.nodes[1].rotation, glm::angleAxis(glm::radians(22.5f), glm::vec3(0, 1, 0)));
  s.animate(1.0, 0);  // only "move"
  EXPECT_NEAR(s.nodes[0].world[3].x, 2.0f, 1e-6f);
  Scene all = twoClipScene();
  all.animate(1.0);
  EXPECT_NEAR(all.nodes[0].world[3].x, 2.0f, 1e-6f);
  expectSameRotation(all.nodes[1].rotation,
                     glm::angleAxis(glm::radians(22.5f), glm::vec3(0, 1, 0)));
}

TEST(AnimationScene, Deterministic) {
  Scene a = twoClipScene(), b = twoClipScene();
  a.animate(0.3);
  a.animate(1.7);
  b.animate(1.7);
  for (size_t n = 0; n < a.nodes.size(); ++n)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_EQ(a.nodes[n].world[c][r], b.nodes[n].world[c][r]);
}

// ---- loader --------------------------------------------------------------------------------

std::string base64(const std::vector<uint8_t>& data) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    uint32_t n = uint32_t(data[i]) << 16;
    if (i + 1 < data.size()) n |= uint32_t(data[i + 1]) << 8;
    if (i + 2 < data.size()) n |= data[i + 2];
    out += k[(n >> 18) & 63];
    out += k[(n >> 12) & 63];
    out += i + 1 < data.size() ? k[(n >> 6) & 63] : '=';
    out += i + 2 < data.size() ? k[n & 63] : '=';
  }
  return out;
}

// A one-triangle glTF whose node 0 is animated by one sampler (times, values as floats).
struct AnimatedGltf {
  std::vector<float> times = {0.0f, 1.0f};
  std::vector<float> values = {0, 0, 0, 1, 2, 3};
  std::string interpolation = "LINEAR";
  std::string path = "translation";
  int channelSampler = 0;
  int outputCount = -1;  // -1: values.size() / 3

  std::string write(const std::string& name) const {
    std::vector<float> floats = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    floats.insert(floats.end(), times.begin(), times.end());
    floats.insert(floats.end(), values.begin(), values.end());
    std::vector<uint8_t> bytes(floats.size() * 4);
    std::memcpy(bytes.data(), floats.data(), bytes.size());
    const size_t timesOffset = 36, valuesOffset = 36 + times.size() * 4;
    json doc = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
        {"buffers",
         {{{"byteLength", bytes.size()},
           {"uri", "data:application/octet-stream;base64," + base64(bytes)}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteLength", bytes.size()}}}},
        {"accessors",
         {{{"bufferView", 0},
           {"componentType", 5126},
           {"count", 3},
           {"type", "VEC3"},
           {"min", {0, 0, 0}},
           {"max", {1, 1, 0}}},
          {{"bufferView", 0},
           {"byteOffset", timesOffset},
           {"componentType", 5126},
           {"count", times.size()},
           {"type", "SCALAR"}},
          {{"bufferView", 0},
           {"byteOffset", valuesOffset},
           {"componentType", 5126},
           {"count", outputCount >= 0 ? size_t(outputCount) : values.size() / 3},
           {"type", "VEC3"}}}},
        {"animations",
         {{{"channels", {{{"sampler", channelSampler}, {"target", {{"node", 0}, {"path", path}}}}}},
           {"samplers", {{{"input", 1}, {"output", 2}, {"interpolation", interpolation}}}}}}}};
    const std::string path = (std::filesystem::temp_directory_path() / name).string();
    std::ofstream(path) << doc.dump();
    return path;
  }
};

void expectLoadError(const std::string& path, ErrorKind kind, const std::string& part) {
  try {
    loadGltf(path);
    ADD_FAILURE() << "expected an error loading " << path;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(AnimationLoader, LoadsASampler) {
  const std::string path = AnimatedGltf{}.write("gi_anim_ok.gltf");
  Scene s = loadGltf(path);
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_FLOAT_EQ(s.animations[0].duration, 1.0f);
  s.animate(0.5);
  EXPECT_NEAR(s.nodes[0].world[3].x, 0.5f, 1e-6f);
  EXPECT_NEAR(s.nodes[0].world[3].y, 1.0f, 1e-6f);
  EXPECT_NEAR(s.nodes[0].world[3].z, 1.5f, 1e-6f);
}

TEST(AnimationLoader, RejectsBadSamplerIndex) {
  AnimatedGltf g;
  g.channelSampler = 3;
  expectLoadError(g.write("gi_anim_badsampler.gltf"), ErrorKind::IndexOutOfRange, "sampler 3");
}

TEST(AnimationLoader, RejectsOutputCountMismatch) {
  AnimatedGltf g;
  g.values = {0, 0, 0, 1, 2, 3, 4, 5, 6};  // 3 values for 2 times
  expectLoadError(g.write("gi_anim_count.gltf"), ErrorKind::InvalidData, "need 2");
  AnimatedGltf cubic;
  cubic.interpolation = "CUBICSPLINE";  // needs 6 elements for 2 keys
  expectLoadError(cubic.write("gi_anim_cubic.gltf"), ErrorKind::InvalidData, "CUBICSPLINE");
}

TEST(AnimationLoader, RejectsNonIncreasingTimes) {
  AnimatedGltf g;
  g.times = {1.0f, 1.0f};
  expectLoadError(g.write("gi_anim_times.gltf"), ErrorKind::InvalidData, "strictly increasing");
}

TEST(AnimationLoader, RejectsUnknownInterpolationAndWrongPathType) {
  AnimatedGltf g;
  g.interpolation = "BEZIER";
  expectLoadError(g.write("gi_anim_interp.gltf"), ErrorKind::Schema, "BEZIER");
  AnimatedGltf r;
  r.path = "rotation";  // VEC3 output for a rotation
  expectLoadError(r.write("gi_anim_rot.gltf"), ErrorKind::Schema, "VEC4");
}

// ---- real files ----------------------------------------------------------------------------

double modelSize(const Scene& s) {
  glm::vec3 lo, hi;
  s.worldBounds(lo, hi);
  return glm::length(hi - lo);
}

// Skinned vertices (CPU reference) of every skinned node, in world space.
std::vector<glm::vec3> skinnedWorldPositions(const Scene& s) {
  std::vector<glm::vec3> out;
  for (size_t n = 0; n < s.nodes.size(); ++n) {
    const Node& node = s.nodes[n];
    for (int m : node.meshes) {
      const Mesh& mesh = s.meshes[m];
      const std::vector<Vertex> v =
          skinVertices(mesh, morphVertices(mesh, node.morphWeights), jointMatrices(s, int(n)));
      for (const Vertex& x : v) out.push_back(glm::vec3(node.world * glm::vec4(x.position, 1)));
    }
  }
  return out;
}

void expectSkinSane(const Scene& s) {
  for (const Mesh& m : s.meshes) {
    if (!m.skinned()) continue;
    ASSERT_EQ(m.weights.size(), m.vertices.size());
    for (const glm::vec4& w : m.weights) {
      const float sum = w.x + w.y + w.z + w.w;
      EXPECT_TRUE(sum == 0.0f || std::abs(sum - 1.0f) < 1e-5f) << sum;
    }
  }
}

TEST(AnimationFiles, SimpleSkin) {
  Scene s = loadGltf(test::assimpModel("glTF2/simple_skin/simple_skin.gltf"));
  ASSERT_EQ(s.skins.size(), 1u);
  EXPECT_EQ(s.skins[0].joints.size(), 2u);
  ASSERT_EQ(s.animations.size(), 1u);
  bool skinned = false;
  for (const Mesh& m : s.meshes) skinned |= m.skinned();
  EXPECT_TRUE(skinned);
  expectSkinSane(s);
  s.animate(0.0);
  const auto a = skinnedWorldPositions(s);
  s.animate(1.0);  // the joint is bent by 90 degrees at 1 s
  const auto b = skinnedWorldPositions(s);
  ASSERT_EQ(a.size(), b.size());
  double moved = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    moved = std::max(moved, double(glm::length(a[i] - b[i])));
    EXPECT_TRUE(std::isfinite(b[i].x) && std::isfinite(b[i].y) && std::isfinite(b[i].z));
  }
  EXPECT_GT(moved, 0.01 * modelSize(s));
}

TEST(AnimationFiles, AnimatedMorphCube) {
  const std::string path =
      test::assimpModel("glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " absent";
  Scene s = loadGltf(path);
  ASSERT_EQ(s.animations.size(), 1u);
  ASSERT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.meshes[0].morphTargets.size(), 2u);
  EXPECT_EQ(s.animations[0].channels[0].path, AnimationPath::Weights);
  int node = -1;
  for (size_t n = 0; n < s.nodes.size(); ++n)
    if (!s.nodes[n].meshes.empty()) node = int(n);
  ASSERT_GE(node, 0);
  const double d = s.animations[0].duration;
  std::vector<float> prev;
  bool changed = false;
  for (double t : {0.0, 0.25 * d, 0.5 * d, 0.75 * d}) {
    s.animate(t);
    ASSERT_EQ(s.nodes[node].morphWeights.size(), 2u);
    const std::vector<Vertex> v = morphVertices(s.meshes[0], s.nodes[node].morphWeights);
    std::vector<float> flat;
    for (const Vertex& x : v) {
      flat.insert(flat.end(), {x.position.x, x.position.y, x.position.z});
      EXPECT_NEAR(glm::length(x.normal), 1.0f, 1e-4f);
    }
    if (!prev.empty() && flat != prev) changed = true;
    prev = flat;
  }
  EXPECT_TRUE(changed);
  // Weights (1, 0) add target 0's deltas exactly.
  const std::vector<Vertex> one = morphVertices(s.meshes[0], {1.0f, 0.0f});
  for (size_t v = 0; v < one.size(); ++v) {
    const glm::vec3 want =
        s.meshes[0].vertices[v].position + s.meshes[0].morphTargets[0].positionDeltas[v];
    EXPECT_NEAR(glm::length(one[v].position - want), 0.0f, 1e-6f);
  }
}

TEST(AnimationFiles, CesiumMan) {
  const std::string path = gi::test::modelAsset("cesium_man/glTF/CesiumMan.gltf");
  Scene s = loadGltf(path);
  ASSERT_EQ(s.skins.size(), 1u);
  EXPECT_EQ(s.skins[0].joints.size(), 19u);
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_GT(s.animations[0].duration, 0.5f);
  expectSkinSane(s);
  s.animate(0.0);
  const auto a = skinnedWorldPositions(s);
  s.animate(0.5);
  const auto b = skinnedWorldPositions(s);
  double moved = 0.0;
  for (size_t i = 0; i < a.size(); ++i) moved = std::max(moved, double(glm::length(a[i] - b[i])));
  EXPECT_GT(moved, 0.01 * modelSize(s));
  // Looping: one period later gives the same pose.
  s.animate(0.5 + s.animations[0].duration);
  const auto c = skinnedWorldPositions(s);
  for (size_t i = 0; i < b.size(); ++i) EXPECT_NEAR(glm::length(b[i] - c[i]), 0.0f, 1e-4f);
}

TEST(AnimationFiles, FoxHasThreeClips) {
  const std::string path = gi::test::modelAsset("fox/glTF/Fox.gltf");
  Scene s = loadGltf(path);
  ASSERT_EQ(s.animations.size(), 3u);
  EXPECT_EQ(s.animations[0].name, "Survey");
  EXPECT_EQ(s.animations[1].name, "Walk");
  EXPECT_EQ(s.animations[2].name, "Run");
  expectSkinSane(s);
  // Different clips give different poses at the same time.
  s.animate(0.4, 1);
  const auto walk = skinnedWorldPositions(s);
  Scene r = loadGltf(path);
  r.animate(0.4, 2);
  const auto run = skinnedWorldPositions(r);
  double diff = 0.0;
  for (size_t i = 0; i < walk.size(); ++i)
    diff = std::max(diff, double(glm::length(walk[i] - run[i])));
  EXPECT_GT(diff, 0.01 * modelSize(s));
}

// ---- CPU skinning ----------------------------------------------------------------------------

TEST(CpuSkinning, ZeroWeightsKeepTheBindPoseAndWeightsAreNormalised) {
  Mesh m;
  m.vertices = {{glm::vec3(1, 2, 3), glm::vec3(0, 1, 0), {}},
                {glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), {}},
                {glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), {}}};
  m.joints = {glm::uvec4(0), glm::uvec4(0, 1, 0, 0), glm::uvec4(1, 0, 0, 0)};
  m.weights = {glm::vec4(0.0f), glm::vec4(2, 2, 0, 0), glm::vec4(5, 0, 0, 0)};
  const std::vector<glm::mat4> joints = {
      glm::translate(glm::mat4(1.0f), glm::vec3(10, 0, 0)),
      glm::scale(glm::mat4(1.0f), glm::vec3(0.0f))};  // a joint collapsed to a point
  const std::vector<Vertex> out = skinVertices(m, m.vertices, joints);
  EXPECT_EQ(out[0].position, glm::vec3(1, 2, 3));  // no weights: bind pose, not the origin
  EXPECT_EQ(out[0].normal, glm::vec3(0, 1, 0));
  // Non-normalised (2, 2): half of each joint.
  EXPECT_NEAR(glm::length(out[1].position - glm::vec3(5.5f, 0, 0)), 0.0f, 1e-6f);
  // Only the zero-scale joint: the position collapses, the normal stays finite (rest normal).
  EXPECT_NEAR(glm::length(out[2].position), 0.0f, 1e-6f);
  EXPECT_EQ(out[2].normal, glm::vec3(1, 0, 0));
  for (const Vertex& v : out) EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-5f);
}

}  // namespace
}  // namespace gi
