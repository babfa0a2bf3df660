// The "surface_points" GPU pass: points evaluated from the deformed vertices equal the CPU
// reference and stay on the skinned surface after several animation steps; the pass exists
// only when points were asked for and something reads them; the "points" view shows them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/animation.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "gi/surface_points.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

class SurfacePointsGpuTest : public VulkanTest {};

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

double sceneSize(const Scene& s) {
  glm::vec3 lo, hi;
  s.worldBounds(lo, hi);
  return glm::length(hi - lo);
}

// Renders the points view at each time and compares every GPU point with the CPU reference
// on the same pose: same position within 1e-4 of the scene size, same normal within 1e-3.
void expectGpuPointsMatchCpu(vk::Context& ctx, const Scene& scene, uint32_t count,
                             const std::vector<double>& times) {
  RenderSettings rs;
  rs.width = 96;
  rs.height = 72;
  rs.surfacePoints = count;
  rs.view = "points";
  Renderer r(ctx, scene, rs);
  ASSERT_TRUE(contains(r.passNames(), "surface_points"));
  EXPECT_TRUE(r.readSurfacePoints().empty()) << "no frame has evaluated the points yet";
  const SurfacePointSet& set = r.surfacePoints();
  ASSERT_EQ(set.points.size(), count);
  const double size = sceneSize(scene);
  Scene cpu = scene;
  for (double t : times) {
    r.setTime(t);
    r.renderFrame();
    cpu.animate(t);
    const std::vector<SurfacePointSample> gpu = r.readSurfacePoints();
    const std::vector<SurfacePointSample> want = evaluateSurfacePoints(cpu, set);
    ASSERT_EQ(gpu.size(), want.size());
    double worstPos = 0.0, worstNormal = 0.0;
    for (size_t i = 0; i < gpu.size(); ++i) {
      ASSERT_TRUE(finite(gpu[i].position) && finite(gpu[i].normal)) << i;
      worstPos = std::max(worstPos, double(glm::length(gpu[i].position - want[i].position)));
      worstNormal = std::max(worstNormal, double(glm::length(gpu[i].normal - want[i].normal)));
      ASSERT_EQ(gpu[i].material, want[i].material);
      ASSERT_NEAR(gpu[i].area, want[i].area, 1e-6 * want[i].area);
    }
    EXPECT_LE(worstPos, 1e-4 * size) << "time " << t;
    EXPECT_LE(worstNormal, 1e-3) << "time " << t;
  }
}

TEST_F(SurfacePointsGpuTest, FollowSimpleSkin) {
  expectGpuPointsMatchCpu(ctx(), loadGltf(test::assimpModel("glTF2/simple_skin/simple_skin.gltf")),
                          20000, {0.0, 0.6, 1.4, 3.1});
}

TEST_F(SurfacePointsGpuTest, FollowCesiumMan) {
  const std::string path = gi::test::modelAsset("cesium_man/glTF/CesiumMan.gltf");
  expectGpuPointsMatchCpu(ctx(), loadGltf(path), 100000, {0.25, 0.9, 1.7});
}

TEST_F(SurfacePointsGpuTest, FollowMorphTargets) {
  expectGpuPointsMatchCpu(
      ctx(),
      loadGltf(test::assimpModel(
          "glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf")),
      5000, {0.0, 0.5, 1.0});
}

TEST_F(SurfacePointsGpuTest, RigidSceneMatchesCpu) {
  expectGpuPointsMatchCpu(ctx(), makeDefaultScene(), 30000, {0.0, 0.7});
}

// One quad (two triangles, 4 vertices) in the xz plane with material `material`; `strayIndex`
// appends a 7th index (a scene built in code may have one: triangle lists ignore it).
Mesh quad(float size, uint32_t material, bool strayIndex = false) {
  Mesh m;
  const float h = 0.5f * size;
  for (glm::vec2 c : {glm::vec2(-h, -h), glm::vec2(h, -h), glm::vec2(h, h), glm::vec2(-h, h)})
    m.vertices.push_back({{c.x, 0.0f, c.y}, {0, 1, 0}, {0, 0}});
  m.indices = {0, 2, 1, 0, 3, 2};
  if (strayIndex) m.indices.push_back(0);
  m.material = material;
  m.boundsMin = {-h, 0, -h};
  m.boundsMax = {h, 0, h};
  return m;
}

// Rigid and skinned instances together: a mesh drawn by two nodes (one mirrored: its normals
// must flip consistently), a material index past the end (clamped on both sides), a mesh
// whose index count is not a multiple of 3 before another one (its first index is not a
// multiple of 3 either), and a skinned character, through several animation steps.
TEST_F(SurfacePointsGpuTest, MixedRigidInstancedMirroredAndSkinned) {
  Scene scene = loadGltf(test::assimpModel("glTF2/simple_skin/simple_skin.gltf"));
  scene.meshes.push_back(quad(1.0f, 0, true));
  scene.meshes.push_back(quad(3.0f, 7));
  const int stray = int(scene.meshes.size()) - 2, mesh = stray + 1;
  const int a = scene.addNode("quad", glm::translate(glm::mat4(1.0f), glm::vec3(0, -1, 0)));
  const int b = scene.addNode(
      "mirrored quad",
      glm::scale(glm::translate(glm::mat4(1.0f), {0, 2, 0}), glm::vec3(-1.0f, 1.0f, 1.0f)));
  const int c = scene.addNode("small quad", glm::translate(glm::mat4(1.0f), glm::vec3(2, 0, 0)));
  scene.nodes[a].meshes.push_back(mesh);
  scene.nodes[b].meshes.push_back(mesh);
  scene.nodes[c].meshes.push_back(stray);
  scene.updateWorldTransforms();
  expectGpuPointsMatchCpu(ctx(), scene, 30000, {0.0, 0.8, 2.2});
}

// The points are re-evaluated only in frames after the pose changed: once for a static scene
// however many frames run, once per new animation time for a skinned one, and not again when
// the time repeats (the points stay those of that pose: checked against the CPU above).
TEST_F(SurfacePointsGpuTest, ReevaluatedOnlyWhenThePoseChanges) {
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  rs.surfacePoints = 2000;
  rs.view = "points";
  Scene still;
  still.meshes.push_back(quad(1.0f, 0));
  still.materials.emplace_back();
  still.nodes[still.addNode("quad", glm::mat4(1.0f))].meshes.push_back(0);
  still.updateWorldTransforms();
  Renderer r(ctx(), still, rs);
  EXPECT_EQ(r.surfacePointEvaluations(), 0u);
  for (double t : {0.0, 0.5, 1.0}) {
    r.setTime(t);
    r.renderFrame();
  }
  EXPECT_EQ(r.surfacePointEvaluations(), 1u);

  const Scene skin = loadGltf(test::assimpModel("glTF2/simple_skin/simple_skin.gltf"));
  Renderer s(ctx(), skin, rs);
  for (double t : {0.0, 0.6, 1.4, 1.4, 1.4}) {
    s.setTime(t);
    s.renderFrame();
  }
  EXPECT_EQ(s.surfacePointEvaluations(), 3u);
}

// Points asked for on a scene without area: none exist, the view still renders (cleared)
// without validation errors and the read-back is empty.
TEST_F(SurfacePointsGpuTest, NoAreaGivesNoPointsAndAnEmptyView) {
  Scene scene;
  Mesh m;
  m.vertices = {{{0, 0, 0}, {0, 1, 0}, {0, 0}},
                {{1, 1, 1}, {0, 1, 0}, {0, 0}},
                {{2, 2, 2}, {0, 1, 0}, {0, 0}}};
  m.indices = {0, 1, 2};
  scene.meshes.push_back(m);
  scene.materials.emplace_back();
  scene.nodes[scene.addNode("line", glm::mat4(1.0f))].meshes.push_back(0);
  scene.updateWorldTransforms();
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  rs.surfacePoints = 1000;
  rs.view = "points";
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  EXPECT_TRUE(r.surfacePoints().points.empty());
  EXPECT_TRUE(r.readSurfacePoints().empty());
  const ImageRGBA32F img = r.readTarget("points");
  for (size_t i = 0; i < img.pixels.size(); i += 4)
    ASSERT_EQ(img.pixels[i] + img.pixels[i + 1] + img.pixels[i + 2], 0.0f);
}

TEST_F(SurfacePointsGpuTest, PassOnlyWhenAskedForAndRead) {
  const Scene scene = makeDefaultScene();
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  {
    Renderer none(ctx(), scene, rs);  // nobody asked for points
    EXPECT_FALSE(contains(none.passNames(), "surface_points"));
    EXPECT_FALSE(contains(none.culledPassNames(), "surface_points"));
    EXPECT_TRUE(none.surfacePoints().points.empty());
  }
  rs.surfacePoints = 1000;
  {
    Renderer unread(ctx(), scene, rs);  // points exist but the final image does not read them
    EXPECT_FALSE(contains(unread.passNames(), "surface_points"));
    EXPECT_TRUE(contains(unread.culledPassNames(), "surface_points"));
    EXPECT_TRUE(contains(unread.culledPassNames(), "points_view"));
  }
  rs.view = "points";
  Renderer viewed(ctx(), scene, rs);
  const std::vector<std::string> want = {"gbuffer", "surface_points", "points_view"};
  EXPECT_EQ(viewed.passNames(), want);
}

// The debug view: points are splatted where they lie on visible surfaces. On the default
// room (every pixel covered by a surface) with 4 points per pixel, most pixels receive one,
// the splat colours are the normals' (finite, in [0, 1]), and no sky pixel is touched.
TEST_F(SurfacePointsGpuTest, ViewShowsPointsOnVisibleSurfaces) {
  const Scene scene = makeDefaultScene();
  RenderSettings rs;
  rs.width = 80;
  rs.height = 60;
  rs.view = "points";
  rs.surfacePoints = 200000;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  const ImageRGBA32F img = r.readTarget("points");
  const ImageRGBA32F depth = r.readTarget("depth");
  size_t covered = 0, surface = 0;
  for (size_t i = 0; i < size_t(img.width) * img.height; ++i) {
    const float* p = &img.pixels[i * 4];
    const bool hit = p[0] + p[1] + p[2] > 0.0f;
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(p[c] >= 0.0f && p[c] <= 1.0f) << i;
    if (depth.pixels[i * 4] <= 0.0f) {
      EXPECT_FALSE(hit) << "sky pixel " << i;
      continue;
    }
    ++surface;
    covered += hit;
  }
  EXPECT_GT(double(covered), 0.9 * double(surface));
}

}  // namespace
}  // namespace gi
