// Animation in JSON scenes: models keep their skins, clips and morph weights when placed by a
// scene (detail::mergeScene), the "animation" object of models, lights and the camera (keyed
// tracks, orbits, validation), "clip" selection, the default scene's bouncing sphere and the
// example assets/scenes/animated.json. CPU only.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <unistd.h>
#include <glm/gtc/matrix_transform.hpp>

#include "gi/animation.h"
#include "gi/errors.h"
#include "gi/scene_io.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace gi {
namespace {

// A fresh folder per test for files written on the fly.
class TempDir : public gi::test::TempDir {
 public:
  TempDir() : gi::test::TempDir("test_json_anim") {}
};

void expectError(const std::function<void()>& load, ErrorKind kind, const std::string& file,
                 const std::string& fragment) {
  try {
    load();
    ADD_FAILURE() << "expected " << errorKindName(kind) << " containing '" << fragment << "'";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << "got " << errorKindName(e.kind()) << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

void expectVec(const glm::vec3& a, const glm::vec3& b, float eps = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, eps) << "(" << a.x << ", " << a.y << ", " << a.z << ")";
  EXPECT_NEAR(a.y, b.y, eps) << "(" << a.x << ", " << a.y << ", " << a.z << ")";
  EXPECT_NEAR(a.z, b.z, eps) << "(" << a.x << ", " << a.y << ", " << a.z << ")";
}

void expectMat(const glm::mat4& a, const glm::mat4& b, float eps) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(a[c][r], b[c][r], eps) << "[" << c << "][" << r << "]";
}

int nodeNamed(const Scene& s, const std::string& name) {
  for (size_t n = 0; n < s.nodes.size(); ++n)
    if (s.nodes[n].name == name) return int(n);
  ADD_FAILURE() << "no node named " << name;
  return -1;
}

glm::vec3 position(const Scene& s, int node) {
  return glm::vec3(s.nodes[node].world[3]);
}
// Where the node's -z (a light's or camera's forward) points in the world.
glm::vec3 forward(const Scene& s, int node) {
  return glm::normalize(glm::vec3(s.nodes[node].world * glm::vec4(0, 0, -1, 0)));
}

// ---- models placed by a scene keep their animation ------------------------------------------

// The merged copy of `alone` (a model file loaded by itself) under root node `root` of
// `merged` poses exactly as the file does: same joint matrices (in the skinned node's mesh
// space, which the placement cancels out of) and morph weights, at every time.
void expectSamePoses(Scene& merged, int root, Scene& alone, const std::vector<double>& times) {
  const int offset = root + 1;  // the model's nodes follow its root, in file order
  ASSERT_LE(size_t(offset) + alone.nodes.size(), merged.nodes.size());
  std::vector<std::vector<glm::mat4>> previous;
  bool changed = false;
  for (double t : times) {
    SCOPED_TRACE("t = " + std::to_string(t));
    merged.animate(t);
    alone.animate(t);
    std::vector<std::vector<glm::mat4>> poses;
    for (size_t n = 0; n < alone.nodes.size(); ++n) {
      const Node& a = alone.nodes[n];
      const Node& m = merged.nodes[offset + n];
      EXPECT_EQ(m.name, a.name);
      EXPECT_EQ(m.morphWeights, a.morphWeights) << a.name;
      const std::vector<glm::mat4> ja = jointMatrices(alone, int(n));
      const std::vector<glm::mat4> jm = jointMatrices(merged, offset + int(n));
      ASSERT_EQ(ja.size(), jm.size()) << a.name;
      for (size_t j = 0; j < ja.size(); ++j) expectMat(jm[j], ja[j], 1e-4f);
      poses.push_back(ja);
      for (float w : a.morphWeights) poses.push_back({glm::mat4(w)});
    }
    if (!previous.empty() && poses != previous) changed = true;
    previous = std::move(poses);
  }
  EXPECT_TRUE(changed) << "the model did not move between the sampled times";
}

TEST(JsonAnimation, MergedModelsKeepSkinsClipsAndMorphWeights) {
  const std::string skin = test::assimpModel("glTF2/simple_skin/simple_skin.gltf");
  const std::string cube =
      test::assimpModel("glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf");
  if (!fs::exists(skin) || !fs::exists(cube)) GTEST_SKIP() << "assimp test models absent";
  TempDir dir;
  const std::string path = dir.write("s.json", R"({
    "models": [
      { "primitive": "plane", "size": 4 },
      { "file": "${ASSIMP_MODELS}/glTF2/simple_skin/simple_skin.gltf", "name": "skin",
        "translation": [2, 0, -1], "rotation": [0, 30, 0], "scale": 0.5 },
      { "file": "${ASSIMP_MODELS}/glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
        "name": "cube", "translation": [-1, 0.5, 0] }
    ],
    "camera": { "position": [0, 1, 5], "target": [0, 0, 0] }
  })");
  Scene merged = loadScene(path);
  Scene skinAlone = loadGltf(skin);
  Scene cubeAlone = loadGltf(cube);
  ASSERT_EQ(merged.skins.size(), skinAlone.skins.size() + cubeAlone.skins.size());
  ASSERT_EQ(merged.animations.size(), skinAlone.animations.size() + cubeAlone.animations.size());
  const int skinRoot = nodeNamed(merged, "skin");
  const int cubeRoot = nodeNamed(merged, "cube");
  ASSERT_GE(skinRoot, 0);
  ASSERT_GE(cubeRoot, 0);
  // Skins point at the merged joints; skinned nodes at the merged skin.
  for (size_t n = 0; n < skinAlone.nodes.size(); ++n) {
    const int s = skinAlone.nodes[n].skin;
    EXPECT_EQ(merged.nodes[skinRoot + 1 + n].skin, s);  // the first skin of the scene
    if (s < 0) continue;
    for (size_t j = 0; j < skinAlone.skins[s].joints.size(); ++j)
      EXPECT_EQ(merged.skins[s].joints[j], skinAlone.skins[s].joints[j] + skinRoot + 1);
  }
  for (const AnimationClip& clip : merged.animations)
    for (const AnimationChannel& ch : clip.channels) {
      ASSERT_GE(ch.node, 0);
      ASSERT_LT(size_t(ch.node), merged.nodes.size());
    }
  {
    SCOPED_TRACE("simple_skin");
    expectSamePoses(merged, skinRoot, skinAlone, {0.0, 1.0, 2.5});
  }
  {
    SCOPED_TRACE("AnimatedMorphCube");
    const double d = cubeAlone.animations.at(0).duration;
    expectSamePoses(merged, cubeRoot, cubeAlone, {0.1 * d, 0.4 * d, 0.7 * d});
  }
  // The placement still applies: the skinned node sits under the scaled, moved root.
  merged.animate(0.0);
  expectVec(position(merged, skinRoot + 1), {2, 0, -1});
}

TEST(JsonAnimation, ClipSelection) {
  const std::string skin = test::assimpModel("glTF2/simple_skin/simple_skin.gltf");
  if (!fs::exists(skin)) GTEST_SKIP() << skin << " absent";
  TempDir dir;
  const std::string model = R"("file": "${ASSIMP_MODELS}/glTF2/simple_skin/simple_skin.gltf")";
  Scene s = loadScene(dir.write("a.json", "{\"models\": [{" + model + ", \"clip\": 0}]}"));
  EXPECT_EQ(s.animations.size(), 1u);
  s = loadScene(dir.write("b.json", "{\"models\": [{" + model + ", \"clip\": \"animation 0\"}]}"));
  EXPECT_EQ(s.animations.size(), 1u);
  std::string p = dir.write("c.json", "{\"models\": [{" + model + ", \"clip\": \"Jump\"}]}");
  expectError([&] { loadScene(p); }, ErrorKind::InvalidData, p,
              "models[0].clip: no clip named 'Jump' in simple_skin.gltf (clips: 'animation 0')");
  p = dir.write("d.json", "{\"models\": [{" + model + ", \"clip\": 1}]}");
  expectError([&] { loadScene(p); }, ErrorKind::InvalidData, p, "models[0].clip: no clip 1");
  p = dir.write("e.json", "{\"models\": [{" + model + ", \"clip\": [0]}]}");
  expectError([&] { loadScene(p); }, ErrorKind::Schema, p, "models[0].clip");
  p = dir.write("f.json", R"({"models": [{"primitive": "box", "clip": 0}]})");
  expectError([&] { loadScene(p); }, ErrorKind::Schema, p, "models[0].clip: unknown key");

  const std::string fox = gi::test::modelAsset("fox/glTF/Fox.gltf");
  Scene f = loadScene(
      dir.write("fox.json", "{\"models\": [{\"file\": \"" + fox + "\", \"clip\": \"Walk\"}]}"));
  ASSERT_EQ(f.animations.size(), 1u);
  EXPECT_EQ(f.animations[0].name, "Walk");
}

// ---- the "animation" object ---------------------------------------------------------------

TEST(JsonAnimation, ModelTracksReplaceTheirPartOfTheTransform) {
  TempDir dir;
  Scene s = loadScene(dir.write("s.json", R"({
    "models": [
      { "primitive": "box", "name": "mover", "translation": [9, 9, 9], "scale": 2,
        "rotation": [0, 90, 0],
        "animation": { "translation": { "times": [0, 1, 2],
                                        "values": [[0, 0, 0], [2, 0, 0], [2, 4, 0]] } } },
      { "primitive": "sphere", "name": "stepper",
        "animation": { "rotation": { "times": [0, 1], "interpolation": "step",
                                     "values": [[0, 0, 0], [0, 0, 0.7071068, 0.7071068]] },
                       "scale": { "times": [0, 2], "interpolation": "cubicspline",
                                  "values": [0, 1, 0,  0, 3, 0] } } }
    ],
    "camera": { "position": [0, 1, 5], "target": [0, 0, 0] }
  })"));
  ASSERT_EQ(s.animations.size(), 2u);
  EXPECT_FLOAT_EQ(s.animations[0].duration, 2.0f);
  EXPECT_FLOAT_EQ(s.animations[1].duration, 2.0f);
  EXPECT_NE(s.animations[0].name.find("models[0].animation"), std::string::npos);
  const int mover = nodeNamed(s, "mover"), stepper = nodeNamed(s, "stepper");
  // Before animating: the entry's own transform.
  expectVec(position(s, mover), {9, 9, 9});
  s.animate(0.5);
  expectVec(position(s, mover), {1, 0, 0});  // translation keys are absolute
  // Scale 2 and the Euler rotation (90 degrees about y) stay: local +x goes to world -2z.
  expectVec(glm::vec3(s.nodes[mover].world * glm::vec4(1, 0, 0, 0)), {0, 0, -2});
  s.animate(1.5);
  expectVec(position(s, mover), {2, 2, 0});
  s.animate(3.5);  // loops over the 2 s duration
  expectVec(position(s, mover), {2, 2, 0});

  // STEP rotation: none until 1 s, then 90 degrees about z. Cubic scale 1 -> 3 with zero
  // tangents: 1 + 2 (3u^2 - 2u^3), u = t / 2.
  s.animate(0.99);
  const float u = 0.495f;
  expectVec(glm::vec3(s.nodes[stepper].world * glm::vec4(1, 0, 0, 0)),
            {1.0f + 2.0f * (3 * u * u - 2 * u * u * u), 0, 0});
  s.animate(1.0);
  // Cubic scale with zero tangents from 1 to 3: the midpoint is 2.
  expectVec(glm::vec3(s.nodes[stepper].world * glm::vec4(1, 0, 0, 0)), {0, 2, 0});
}

TEST(JsonAnimation, LightsAndCamera) {
  TempDir dir;
  Scene s = loadScene(dir.write("s.json", R"({
    "models": [ { "primitive": "plane", "size": 10 } ],
    "camera": { "position": [0, 2, 4], "target": [0, 1, 0], "name": "cam",
                "animation": { "orbit": { "period": 8 } } },
    "lights": [
      { "type": "point", "name": "bulb", "position": [0, 3, 0],
        "animation": { "translation": { "times": [0, 4], "values": [[-1, 3, 0], [1, 3, 0]] } } },
      { "type": "spot", "name": "spot", "position": [2, 3, 0], "direction": [0, -1, 0],
        "animation": { "orbit": { "center": [0, 0, 0], "axis": [0, 1, 0], "period": 4 } } },
      { "type": "directional", "name": "sun", "direction": [0, -1, 0],
        "animation": { "direction": { "times": [0, 1],
                                      "values": [[1, -1, 0], [-1, -1, 0]] } } }
    ]
  })"));
  ASSERT_EQ(s.animations.size(), 4u);
  const int cam = nodeNamed(s, "cam"), bulb = nodeNamed(s, "bulb"), spot = nodeNamed(s, "spot"),
            sun = nodeNamed(s, "sun");
  const glm::vec3 target(0, 1, 0);

  // Time 0: every entry where the file puts it.
  s.animate(0.0);
  expectVec(position(s, cam), {0, 2, 4});
  expectVec(position(s, bulb), {-1, 3, 0});
  expectVec(position(s, spot), {2, 3, 0});
  expectVec(forward(s, spot), {0, -1, 0});
  expectVec(forward(s, sun), glm::normalize(glm::vec3(1, -1, 0)));

  // A quarter turn about +y (right-handed): +z goes to +x, +x goes to -z.
  s.animate(2.0);
  expectVec(position(s, cam), {4, 2, 0});
  expectVec(position(s, bulb), {0, 3, 0});
  expectVec(position(s, spot), {-2, 3, 0});  // half a turn of its 4 s period
  s.animate(1.0);
  expectVec(position(s, spot), {0, 3, -2});
  expectVec(forward(s, spot), {0, -1, 0});  // turns with the orbit: still straight down
  s.animate(0.5);
  expectVec(forward(s, sun), {0, -1, 0}, 1e-5f);  // slerped half way, along the great circle
  s.animate(0.75);
  expectVec(forward(s, sun), {-std::sin(glm::radians(22.5f)), -std::cos(glm::radians(22.5f)), 0},
            1e-5f);

  // The orbiting camera keeps looking at its target (the default centre) all the way round,
  // on the circle, and comes back to where it started.
  for (double t = 0.0; t <= 8.0; t += 0.37) {
    s.animate(t);
    const CameraView view = activeCamera(s, 1.0f);
    const glm::vec3 seen = glm::vec3(view.view * glm::vec4(target, 1.0f));
    EXPECT_NEAR(seen.x, 0.0f, 1e-4f) << t;
    EXPECT_NEAR(seen.y, 0.0f, 1e-4f) << t;
    EXPECT_NEAR(seen.z, -std::sqrt(17.0f), 1e-4f) << t;
    const glm::vec3 p = position(s, cam);
    EXPECT_NEAR(glm::length(glm::vec2(p.x, p.z)), 4.0f, 1e-4f) << t;
    EXPECT_NEAR(p.y, 2.0f, 1e-5f) << t;
  }
  s.animate(8.0);
  EXPECT_EQ(position(s, cam), glm::vec3(0, 2, 4));
}

TEST(JsonAnimation, Errors) {
  TempDir dir;
  using K = ErrorKind;
  struct Case {
    const char* name;
    const char* json;
    K kind;
    const char* fragment;
  };
  const Case cases[] = {
      {"not_object", R"({"models": [{"primitive": "box", "animation": []}]})", K::Schema,
       "models[0].animation: expected an object"},
      {"empty", R"({"models": [{"primitive": "box", "animation": {}}]})", K::Schema,
       "models[0].animation: expected at least one of translation"},
      {"unknown_track", R"({"models": [{"primitive": "box", "animation": {"position": {}}}]})",
       K::Schema, "models[0].animation.position: unknown key"},
      {"point_direction",
       R"({"lights": [{"type": "point", "position": [0, 1, 0], "animation": {"direction":
           {"times": [0], "values": [[0, -1, 0]]}}}]})",
       K::Schema, "lights[0].animation.direction: unknown key"},
      {"no_times", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"values": [[0, 0, 0]]}}}]})",
       K::Schema, "models[0].animation.translation.times: missing required key"},
      {"no_values", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0]}}}]})",
       K::Schema, "models[0].animation.translation.values: missing required key"},
      {"empty_times", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [], "values": []}}}]})",
       K::InvalidData, "translation.times: needs at least one key time"},
      {"times_type", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0, "1"], "values": [[0, 0, 0], [1, 1, 1]]}}}]})",
       K::Schema, "translation.times[1]: expected a number, got a string"},
      {"times_order", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0, 1, 1], "values": [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}}}]})",
       K::InvalidData, "translation.times[2]: key times must be strictly increasing"},
      {"times_negative", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [-1, 1], "values": [[0, 0, 0], [1, 1, 1]]}}}]})",
       K::InvalidData, "translation.times[0]: key times must not be negative"},
      {"times_huge", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0, 1e300], "values": [[0, 0, 0], [1, 1, 1]]}}}]})",
       K::InvalidData, "translation.times[1]: number out of range"},
      {"count", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0, 1], "values": [[0, 0, 0]]}}}]})",
       K::InvalidData, "translation.values: 1 values for 2 key times; need 2"},
      {"count_cubic", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0, 1], "interpolation": "cubicspline", "values": [[0, 0, 0], [1, 1, 1]]}}}]})",
       K::InvalidData, "need 6"},
      {"value_length", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0], "values": [[0, 0]]}}}]})",
       K::Schema, "translation.values[0]: expected an array of 3 numbers, got 2 elements"},
      {"value_type", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0], "values": [[0, null, 0]]}}}]})",
       K::Schema, "translation.values[0][1]: expected a number, got null"},
      {"interp", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0], "values": [[0, 0, 0]], "interpolation": "LINEAR"}}}]})",
       K::Schema, "translation.interpolation: unknown interpolation 'LINEAR'"},
      {"track_key", R"({"models": [{"primitive": "box", "animation": {"translation":
           {"times": [0], "values": [[0, 0, 0]], "loop": true}}}]})",
       K::Schema, "translation.loop: unknown key"},
      {"zero_quat", R"({"models": [{"primitive": "box", "animation": {"rotation":
           {"times": [0], "values": [[0, 0, 0, 0]]}}}]})",
       K::InvalidData, "rotation.values[0]: quaternion has zero length"},
      {"cubic_euler", R"({"models": [{"primitive": "box", "animation": {"rotation":
           {"times": [0], "interpolation": "cubicspline",
            "values": [[0, 0, 0, 0], [0, 90, 0], [0, 0, 0, 0]]}}}]})",
       K::Schema, "rotation.values[1]: expected an array of 4 numbers"},
      {"zero_scale", R"({"models": [{"primitive": "box", "animation": {"scale":
           {"times": [0, 1], "values": [1, [1, 0, 1]]}}}]})",
       K::InvalidData, "scale.values[1]: scale must not be zero"},
      {"scale_type", R"({"models": [{"primitive": "box", "animation": {"scale":
           {"times": [0], "values": ["big"]}}}]})",
       K::Schema, "scale.values[0]: expected an array of 3 numbers, got a string"},
      {"zero_direction", R"({"lights": [{"type": "directional", "animation": {"direction":
           {"times": [0], "values": [[0, 0, 0]]}}}]})",
       K::InvalidData, "lights[0].animation.direction.values[0]: direction must not be zero"},
      {"cubic_direction", R"({"lights": [{"type": "directional", "animation": {"direction":
           {"times": [0], "interpolation": "cubicspline", "values": [[0, 0, 0], [0, -1, 0], [0, 0, 0]]}}}]})",
       K::Schema, "direction.interpolation: direction keys take linear or step"},
      {"rotation_and_direction", R"({"lights": [{"type": "directional", "animation": {
           "direction": {"times": [0], "values": [[0, -1, 0]]},
           "rotation": {"times": [0], "values": [[0, 0, 0]]}}}]})",
       K::Schema, "lights[0].animation.direction: give either rotation or direction"},
      {"orbit_and_keys", R"({"lights": [{"type": "point", "position": [1, 1, 1], "animation": {
           "orbit": {"center": [0, 0, 0], "period": 2},
           "translation": {"times": [0], "values": [[0, 0, 0]]}}}]})",
       K::Schema, "lights[0].animation.translation: cannot be combined with \"orbit\""},
      {"orbit_center",
       R"({"models": [{"primitive": "box", "animation": {"orbit": {"period": 2}}}]})", K::Schema,
       "models[0].animation.orbit.center: missing required key"},
      {"orbit_period", R"({"camera": {"position": [0, 0, 1], "target": [0, 0, 0],
           "animation": {"orbit": {"axis": [0, 1, 0]}}}})",
       K::Schema, "camera.animation.orbit.period: missing required key"},
      {"orbit_period_zero", R"({"camera": {"position": [0, 0, 1], "target": [0, 0, 0],
           "animation": {"orbit": {"period": 0}}}})",
       K::InvalidData, "camera.animation.orbit.period: must be positive"},
      {"orbit_axis", R"({"camera": {"position": [0, 0, 1], "target": [0, 0, 0],
           "animation": {"orbit": {"period": 1, "axis": [0, 0, 0]}}}})",
       K::InvalidData, "camera.animation.orbit.axis: must not be zero"},
      {"orbit_key", R"({"camera": {"position": [0, 0, 1], "target": [0, 0, 0],
           "animation": {"orbit": {"period": 1, "speed": 2}}}})",
       K::Schema, "camera.animation.orbit.speed: unknown key"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.write(std::string(c.name) + ".json", c.json);
    expectError([&] { loadScene(path); }, c.kind, path, c.fragment);
  }
}

// ---- the built-in scene's moving object ---------------------------------------------------

TEST(JsonAnimation, DefaultSceneSphereBounces) {
  Scene s = makeDefaultScene();
  const int sphere = nodeNamed(s, "sphere");
  ASSERT_GE(sphere, 0);
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_FLOAT_EQ(s.animations[0].duration, 2.0f);
  // Exactly the old still scene at t = 0 (resting on the short block) and every period.
  const glm::mat4 old = glm::translate(glm::mat4(1.0f), glm::vec3(0.33f, -0.4f + 0.25f, 0.3f));
  EXPECT_EQ(s.nodes[sphere].world, old);
  const std::vector<Node> still = s.nodes;
  s.animate(0.0);
  for (size_t n = 0; n < still.size(); ++n) EXPECT_EQ(s.nodes[n].world, still[n].world) << n;
  s.animate(0.5);
  EXPECT_NEAR(s.nodes[sphere].world[3].y, old[3].y + 0.225f, 1e-5f);  // 4 h u (1 - u), u = 1/4
  EXPECT_NEAR(s.nodes[sphere].world[3].x, old[3].x, 1e-6f);
  EXPECT_NEAR(s.nodes[sphere].world[3].z, old[3].z, 1e-6f);
  s.animate(1.0);
  EXPECT_NEAR(s.nodes[sphere].world[3].y, old[3].y + 0.3f, 1e-5f);  // the top
  s.animate(2.5);                                                   // loops
  EXPECT_NEAR(s.nodes[sphere].world[3].y, old[3].y + 0.225f, 1e-5f);
  s.animate(4.0);
  EXPECT_EQ(s.nodes[sphere].world, old);
  // Never below the resting height: it does not sink into the block.
  for (double t = 0.0; t < 2.0; t += 0.05) {
    s.animate(t);
    EXPECT_GE(s.nodes[sphere].world[3].y, old[3].y - 1e-6f) << t;
  }
  // Only the sphere moves.
  for (size_t n = 0; n < still.size(); ++n)
    if (int(n) != sphere) {
      EXPECT_EQ(s.nodes[n].world, still[n].world) << still[n].name;
    }
}

// ---- assets/scenes/animated.json ----------------------------------------------------------

TEST(JsonAnimation, AnimatedExampleScene) {
  const std::string skin = test::assimpModel("glTF2/simple_skin/simple_skin.gltf");
  const std::string cube =
      test::assimpModel("glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf");
  if (!fs::exists(skin) || !fs::exists(cube)) GTEST_SKIP() << "assimp test models absent";
  const fs::path file = fs::path(GI_SOURCE_DIR) / "assets" / "scenes" / "animated.json";
  Scene s = loadScene(file.string());
  EXPECT_EQ(s.skins.size(), 3u);  // CesiumMan, Fox, simple_skin
  size_t skinnedMeshes = 0, morphed = 0;
  for (size_t n = 0; n < s.nodes.size(); ++n)
    for (int m : s.nodes[n].meshes) {
      if (s.meshes[m].skinned()) {
        ++skinnedMeshes;
        ASSERT_GE(s.nodes[n].skin, 0) << s.nodes[n].name;
        ASSERT_LT(size_t(s.nodes[n].skin), s.skins.size());
        EXPECT_FALSE(jointMatrices(s, int(n)).empty());
      }
      if (!s.meshes[m].morphTargets.empty()) ++morphed;
    }
  EXPECT_GE(skinnedMeshes, 3u);
  EXPECT_GE(morphed, 1u);
  // One clip per animated model (the Fox plays only its walk) plus the spot light's orbit.
  EXPECT_GE(s.animations.size(), 5u);
  int shadowed = 0, spotNode = -1;
  bool sun = false;
  for (size_t n = 0; n < s.nodes.size(); ++n) {
    const int l = s.nodes[n].light;
    if (l < 0) continue;
    shadowed += s.lights[l].castsShadows;
    sun |= s.lights[l].type == LightType::Directional && s.lights[l].castsShadows;
    if (s.lights[l].type == LightType::Spot && s.lights[l].castsShadows) spotNode = int(n);
  }
  EXPECT_TRUE(sun);
  ASSERT_GE(spotNode, 0);
  EXPECT_GE(shadowed, 2);
  ASSERT_EQ(s.effects.size(), 1u);
  EXPECT_EQ(s.effects[0].name, "ssao");

  std::vector<glm::vec3> spotPositions;
  for (double t : {0.0, 0.4, 1.0, 2.7, 5.0, 13.3}) {
    SCOPED_TRACE("t = " + std::to_string(t));
    s.animate(t);
    for (const Node& n : s.nodes) ASSERT_TRUE(finite(n.world)) << n.name;
    for (size_t n = 0; n < s.nodes.size(); ++n)
      for (const glm::mat4& j : jointMatrices(s, int(n))) ASSERT_TRUE(finite(j));
    spotPositions.push_back(position(s, spotNode));
    // Everything stays in front of the camera.
    const CameraView view = activeCamera(s, 4.0f / 3.0f);
    glm::vec3 lo, hi;
    s.worldBounds(lo, hi);
    EXPECT_LT((view.view * glm::vec4(0.5f * (lo + hi), 1.0f)).z, 0.0f);
  }
  EXPECT_GT(glm::length(spotPositions[1] - spotPositions[0]), 0.1f);  // the spot light orbits
}

}  // namespace
}  // namespace gi
