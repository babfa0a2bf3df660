// gi::sceneContentHash: the same for the same content loaded twice or from another path, and
// different after any change a render would see (a vertex, a material, a texel, an
// environment texel, a light, a transform), so caches keyed on it are never stale.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "gi/scene_hash.h"
#include "gi/scene_io.h"
#include "test_support.h"

namespace gi {
namespace {

TEST(SceneContentHash, SameContentSameHashAnyChangeAnother) {
  const std::string text = R"({ "models": [
      { "primitive": "box", "size": 1, "material": { "base_color": [0.5, 0.5, 0.5] } } ],
    "lights": [ { "type": "point", "position": [0, 3, 0] } ],
    "camera": { "position": [0, 1, 5], "target": [0, 0, 0] } })";
  test::TempDir dir("scene_hash");
  const Scene a = loadScene(dir.write("a.json", text));
  const Scene b = loadScene(dir.write("elsewhere/b.json", text));
  const uint64_t base = sceneContentHash(a);
  EXPECT_EQ(base, sceneContentHash(b));
  EXPECT_EQ(base, sceneContentHash(a));

  const std::vector<std::pair<const char*, std::function<void(Scene&)>>> edits = {
      {"vertex", [](Scene& s) { s.meshes[0].vertices[3].position.x += 1e-6f; }},
      {"normal", [](Scene& s) { s.meshes[0].vertices[0].normal.y = -1.0f; }},
      {"index", [](Scene& s) { std::swap(s.meshes[0].indices[0], s.meshes[0].indices[1]); }},
      {"material", [](Scene& s) { s.materials[0].roughness = 0.5f; }},
      {"double-sided", [](Scene& s) { s.materials[0].doubleSided = true; }},
      {"texture",
       [](Scene& s) {
         s.textures.push_back({"t", 1, 1, {1, 2, 3, 4}});
       }},
      {"light", [](Scene& s) { s.lights[0].intensity = 2.0f; }},
      {"transform", [](Scene& s) { s.nodes[0].world[3][0] = 0.25f; }},
      {"environment map",
       [](Scene& s) {
         s.environment.mapWidth = 1;
         s.environment.mapHeight = 1;
         s.environment.mapRGB = {0.0f, 0.0f, 1.0f};
       }},
  };
  for (const auto& [what, edit] : edits) {
    Scene changed = a;
    edit(changed);
    EXPECT_NE(sceneContentHash(changed), base) << what;
  }
  // A texel of an environment map.
  Scene env = a;
  env.environment.mapWidth = 1;
  env.environment.mapHeight = 1;
  env.environment.mapRGB = {0.0f, 0.0f, 1.0f};
  Scene env2 = env;
  env2.environment.mapRGB[1] = 0.5f;
  EXPECT_NE(sceneContentHash(env), sceneContentHash(env2));
}

}  // namespace
}  // namespace gi
