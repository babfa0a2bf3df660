// GPU skinning (the renderer's "skinning" pass) against the CPU reference gi::skinVertices on
// real skinned files and on degenerate skins; renders at different times differ where the
// character moved; the pass exists only for skinned scenes and re-skins only what changed.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/animation.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

class SkinningTest : public VulkanTest {};

double modelSize(const Scene& s) {
  glm::vec3 lo, hi;
  s.worldBounds(lo, hi);
  return glm::length(hi - lo);
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// Renders `scene` at each time and compares the GPU-deformed vertices with the CPU reference.
void expectGpuMatchesCpu(vk::Context& ctx, const Scene& scene, const std::vector<double>& times) {
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  Renderer r(ctx, scene, rs);
  EXPECT_TRUE(contains(r.passNames(), "skinning"));
  const double size = modelSize(scene);
  Scene cpu = scene;
  for (double t : times) {
    r.setTime(t);
    r.renderFrame();
    cpu.animate(t);
    const std::vector<Renderer::DeformedMesh> gpu = r.readDeformedMeshes();
    ASSERT_FALSE(gpu.empty());
    double worstPos = 0.0, worstNormal = 0.0;
    for (const Renderer::DeformedMesh& d : gpu) {
      const Mesh& mesh = cpu.meshes[d.mesh];
      const std::vector<Vertex> want = skinVertices(
          mesh, morphVertices(mesh, cpu.nodes[d.node].morphWeights), jointMatrices(cpu, d.node));
      ASSERT_EQ(want.size(), d.vertices.size());
      for (size_t v = 0; v < want.size(); ++v) {
        ASSERT_TRUE(finite(d.vertices[v].position) && finite(d.vertices[v].normal));
        worstPos =
            std::max(worstPos, double(glm::length(d.vertices[v].position - want[v].position)));
        worstNormal =
            std::max(worstNormal, double(glm::length(d.vertices[v].normal - want[v].normal)));
        EXPECT_EQ(d.vertices[v].uv, want[v].uv);
      }
    }
    EXPECT_LE(worstPos, 1e-4 * size) << "time " << t;
    EXPECT_LE(worstNormal, 1e-4) << "time " << t;
  }
}

TEST_F(SkinningTest, GpuMatchesCpuOnCesiumMan) {
  const std::string path = gi::test::modelAsset("cesium_man/glTF/CesiumMan.gltf");
  expectGpuMatchesCpu(ctx(), loadGltf(path), {0.0, 0.37, 1.1, 1.9});
}

TEST_F(SkinningTest, GpuMatchesCpuOnSimpleSkin) {
  expectGpuMatchesCpu(ctx(), loadGltf(test::assimpModel("glTF2/simple_skin/simple_skin.gltf")),
                      {0.0, 0.75, 1.0, 3.3});
}

TEST_F(SkinningTest, GpuMatchesCpuOnFox) {
  const std::string path = gi::test::modelAsset("fox/glTF/Fox.gltf");
  Scene fox = loadGltf(path);
  fox.animations.resize(1);  // one clip at a time (all clips would fight over the joints)
  expectGpuMatchesCpu(ctx(), fox, {0.0, 1.3});
}

// A quad skinned to two joints; joint 1 is scaled to zero. Vertices: no weights, weights that
// do not sum to 1, only the collapsed joint, and the two mixed.
Scene degenerateSkinScene() {
  Scene s;
  s.sourcePath = "degenerate-skin";
  Mesh m;
  m.name = "quad";
  for (auto [x, y] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}})
    m.vertices.push_back({glm::vec3(x, y, 0), glm::vec3(0, 0, 1), glm::vec2(x, y)});
  m.indices = {0, 1, 2, 0, 2, 3};
  m.boundsMin = glm::vec3(-1, -1, 0);
  m.boundsMax = glm::vec3(1, 1, 0);
  m.triangleAreas = {2, 2};
  m.joints = {glm::uvec4(0), glm::uvec4(0, 1, 0, 0), glm::uvec4(1, 0, 0, 0),
              glm::uvec4(0, 1, 0, 0)};
  m.weights = {glm::vec4(0), glm::vec4(3, 1, 0, 0), glm::vec4(1, 0, 0, 0),
               glm::vec4(0.25f, 0.25f, 0, 0)};
  s.meshes.push_back(m);
  s.materials.push_back(Material{});
  const int root = s.addNode("skinned", glm::mat4(1.0f));
  s.nodes[root].meshes = {0};
  s.nodes[root].skin = 0;
  const int j0 = s.addNode("joint0", glm::translate(glm::mat4(1.0f), glm::vec3(0, 0.5f, 0)));
  const int j1 = s.addNode("joint1", glm::scale(glm::mat4(1.0f), glm::vec3(0.0f)));
  s.skins.push_back({"skin", {j0, j1}, {glm::mat4(1.0f), glm::mat4(1.0f)}});
  s.updateWorldTransforms();
  return s;
}

TEST_F(SkinningTest, DegenerateSkinsStayFinite) {
  Scene scene = degenerateSkinScene();
  expectGpuMatchesCpu(ctx(), scene, {0.0});
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  const auto gpu = r.readDeformedMeshes();
  ASSERT_EQ(gpu.size(), 1u);
  const std::vector<Vertex>& v = gpu[0].vertices;
  for (const Vertex& x : v) {
    EXPECT_TRUE(finite(x.position) && finite(x.normal));
    EXPECT_NEAR(glm::length(x.normal), 1.0f, 1e-4f);
  }
  EXPECT_EQ(v[0].position, glm::vec3(-1, -1, 0));  // zero weights: bind pose, not the origin
  // (3, 1) renormalised: 3/4 of joint 0 (translated by 0.5 in y), 1/4 of the collapsed joint.
  EXPECT_NEAR(glm::length(v[1].position - 0.75f * glm::vec3(1, -0.5f, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(v[2].position), 0.0f, 1e-6f);  // only the collapsed joint
  EXPECT_NEAR(glm::length(v[3].position - 0.5f * glm::vec3(-1, 1.5f, 0)), 0.0f, 1e-5f);
  for (float x : r.readTarget("normal").pixels) ASSERT_TRUE(std::isfinite(x));
}

TEST_F(SkinningTest, RendersDifferWhereTheCharacterMovedAndOnlyChangesAreReskinned) {
  const std::string path = gi::test::modelAsset("cesium_man/glTF/CesiumMan.gltf");
  Scene scene = loadGltf(path);
  RenderSettings rs;
  rs.width = 96;
  rs.height = 72;
  Renderer r(ctx(), scene, rs);
  const std::vector<std::string> passes = r.passNames();
  ASSERT_TRUE(contains(passes, "skinning"));
  EXPECT_LT(std::find(passes.begin(), passes.end(), "skinning") - passes.begin(),
            std::find(passes.begin(), passes.end(), "gbuffer") - passes.begin());
  r.setTime(0.0);
  r.renderFrame();
  EXPECT_GT(r.lastSkinnedVertexCount(), 0u);
  const ImageRGBA32F a = r.readTarget("depth");
  r.setTime(0.0);  // same pose: nothing to re-skin
  r.renderFrame();
  EXPECT_EQ(r.lastSkinnedVertexCount(), 0u);
  r.setTime(0.6);
  r.renderFrame();
  EXPECT_GT(r.lastSkinnedVertexCount(), 0u);
  const ImageRGBA32F b = r.readTarget("depth");
  size_t changed = 0, covered = 0;
  for (size_t i = 0; i < a.pixels.size(); i += 4) {
    covered += a.pixels[i] > 0.0f || b.pixels[i] > 0.0f;
    changed += std::abs(a.pixels[i] - b.pixels[i]) > 1e-6f;
  }
  EXPECT_GT(covered, 0u);
  EXPECT_GT(changed, covered / 50) << "covered " << covered;
  EXPECT_LT(changed, a.pixels.size() / 4);  // the background did not change
}

TEST_F(SkinningTest, NoSkinningPassForStaticScenes) {
  Scene scene = makeDefaultScene();
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  Renderer r(ctx(), scene, rs);
  r.setTime(1.0);
  r.renderFrame();
  EXPECT_FALSE(contains(r.passNames(), "skinning"));
  EXPECT_FALSE(contains(r.culledPassNames(), "skinning"));
}

}  // namespace
}  // namespace gi
