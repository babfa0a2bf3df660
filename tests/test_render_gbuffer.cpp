// G-buffer and lighting on analytic scenes: a plane facing the camera must give the expected
// normal and a depth that reconstructs its position; sky pixels are marked and finite.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

// A square of half-size `half` in the plane z = 0, facing +z.
Mesh makeQuad(float half) {
  Mesh m;
  m.name = "quad";
  for (auto [x, y] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}})
    m.vertices.push_back(
        {glm::vec3(x * half, y * half, 0), glm::vec3(0, 0, 1), glm::vec2(x, y) * 0.5f + 0.5f});
  m.indices = {0, 1, 2, 0, 2, 3};
  m.boundsMin = glm::vec3(-half, -half, 0);
  m.boundsMax = glm::vec3(half, half, 0);
  m.triangleAreas = {2 * half * half, 2 * half * half};
  return m;
}

// Camera at the origin looking down -z (the glTF camera convention), plane at z = -distance.
Scene planeScene(float distance, float half, float znear = 0.1f, float zfar = 100.0f) {
  Scene s;
  s.sourcePath = "analytic-plane";
  s.meshes.push_back(makeQuad(half));
  s.materials.push_back(Material{});
  int plane = s.addNode("plane", glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -distance)));
  s.nodes[plane].meshes = {0};
  Camera cam;
  cam.yfov = glm::radians(60.0f);
  cam.znear = znear;
  cam.zfar = zfar;
  s.cameras.push_back(cam);
  int camNode = s.addNode("camera", glm::mat4(1.0f));
  s.nodes[camNode].camera = 0;
  s.activeCameraNode = camNode;
  Light sun;
  sun.type = LightType::Directional;
  sun.intensity = 2.0f;
  s.lights.push_back(sun);
  int lightNode = s.addNode("sun", glm::mat4(1.0f));
  s.nodes[lightNode].light = 0;
  s.updateWorldTransforms();
  return s;
}

bool allFinite(const ImageRGBA32F& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}

class GBufferTest : public VulkanTest {};

TEST_F(GBufferTest, PlaneFacingCameraHasExpectedNormalAndDepth) {
  const float distance = 5.0f, half = 1.0f;
  Scene scene = planeScene(distance, half);
  RenderSettings rs;
  rs.width = 160;
  rs.height = 120;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  ImageRGBA32F depth = r.readTarget("depth");
  ImageRGBA32F normal = r.readTarget("normal");
  const glm::mat4 invProj = glm::inverse(r.camera().proj);

  int planePixels = 0, skyPixels = 0;
  for (int y = 0; y < int(rs.height); ++y) {
    for (int x = 0; x < int(rs.width); ++x) {
      const size_t i = size_t(y) * rs.width + x;
      const float d = depth.pixels[i * 4];
      const float* n = &normal.pixels[i * 4];
      glm::vec2 uv((x + 0.5f) / rs.width, (y + 0.5f) / rs.height);
      glm::vec4 v = invProj * glm::vec4(uv * 2.0f - 1.0f, d, 1.0f);
      if (d > 0.0f) {
        ++planePixels;
        glm::vec3 pos = glm::vec3(v) / v.w;
        // Depth reconstructs the plane: z within 1e-4 relative (32-bit float reverse-Z).
        EXPECT_NEAR(pos.z, -distance, distance * 1e-4f) << "pixel " << x << "," << y;
        EXPECT_LE(std::abs(pos.x), half * 1.01f);
        EXPECT_LE(std::abs(pos.y), half * 1.01f);
        // Half-float normal (0,0,1): exact to 1e-3; w marks geometry.
        EXPECT_NEAR(n[0], 0.0f, 1e-3f);
        EXPECT_NEAR(n[1], 0.0f, 1e-3f);
        EXPECT_NEAR(n[2], 1.0f, 1e-3f);
        EXPECT_EQ(n[3], 1.0f);
      } else {
        ++skyPixels;
        EXPECT_EQ(n[3], 0.0f) << "sky pixel not marked at " << x << "," << y;
      }
    }
  }
  // The plane's projected size: half-extent / (distance * tan(30deg)) of the half-height.
  const double expectedFraction = std::pow(half / (distance * std::tan(glm::radians(30.0))), 2) *
                                  (double(rs.height) / rs.width);
  EXPECT_NEAR(double(planePixels) / (rs.width * rs.height), expectedFraction, 0.01);
  EXPECT_GT(skyPixels, 0);
  EXPECT_TRUE(allFinite(r.readTarget("lit")));
}

TEST_F(GBufferTest, PlaneWorldPositionReconstructsUnderRotatedCamera) {
  // Camera moved and turned: world position from depth must land on the plane z = -5.
  Scene scene = planeScene(5.0f, 3.0f);
  scene.nodes[scene.activeCameraNode].local =
      glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, 0.3f, 0.0f)) *
      glm::rotate(glm::mat4(1.0f), glm::radians(10.0f), glm::vec3(0, 1, 0));
  scene.updateWorldTransforms();
  RenderSettings rs;
  rs.width = 160;
  rs.height = 120;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  ImageRGBA32F depth = r.readTarget("depth");
  const glm::mat4 invViewProj = glm::inverse(r.camera().proj * r.camera().view);
  int checked = 0;
  for (int y = 0; y < int(rs.height); y += 7) {
    for (int x = 0; x < int(rs.width); x += 7) {
      float d = depth.pixels[(size_t(y) * rs.width + x) * 4];
      if (d <= 0.0f) continue;
      glm::vec2 uv((x + 0.5f) / rs.width, (y + 0.5f) / rs.height);
      glm::vec4 w = invViewProj * glm::vec4(uv * 2.0f - 1.0f, d, 1.0f);
      EXPECT_NEAR(w.z / w.w, -5.0f, 5e-3f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST_F(GBufferTest, NoNanAtGrazingAngleAndExtremeClipPlanes) {
  // Camera skimming along a huge plane with near = 1e-4 and far = 1e5: no NaN/Inf anywhere.
  Scene scene = planeScene(0.0f, 1000.0f, 1e-4f, 1e5f);
  scene.nodes[0].local = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(0, -0.01f, 0)),
                                     glm::radians(-90.0f), glm::vec3(1, 0, 0));
  scene.updateWorldTransforms();
  RenderSettings rs;
  rs.width = 160;
  rs.height = 120;
  // Kept to the end of the frame: otherwise a later pass may reuse their memory (readTarget
  // then refuses them rather than returning another resource's texels).
  rs.keepForReadback = {"depth", "normal", "albedo", "material", "emission", "motion", "lit"};
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  for (const char* t :
       {"depth", "normal", "albedo", "material", "emission", "motion", "lit", "output"})
    EXPECT_TRUE(allFinite(r.readTarget(t))) << "target " << t;
}

TEST_F(GBufferTest, DegenerateTransformGivesFiniteNormals) {
  // A node scaled to zero along one axis: the cofactor normal matrix must stay finite.
  Scene scene = planeScene(5.0f, 1.0f);
  scene.nodes[0].local = glm::scale(scene.nodes[0].local, glm::vec3(1, 1, 0));
  scene.updateWorldTransforms();
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  EXPECT_TRUE(allFinite(r.readTarget("normal")));
  EXPECT_TRUE(allFinite(r.readTarget("lit")));
}

TEST_F(GBufferTest, EmptySceneRendersSkyOnly) {
  Scene scene;
  scene.materials.push_back(Material{});
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  ImageRGBA32F lit = r.readTarget("lit");
  EXPECT_TRUE(allFinite(lit));
  ImageRGBA32F normal = r.readTarget("normal");
  for (size_t i = 3; i < normal.pixels.size(); i += 4) ASSERT_EQ(normal.pixels[i], 0.0f);
}

TEST_F(GBufferTest, TimingsCoverExecutedPasses) {
  Scene scene = planeScene(5.0f, 1.0f);
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  rs.floorPass = true;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  const std::vector<std::string> expected = {"gbuffer", "shadow_0", "lighting", "tonemap", "floor"};
  EXPECT_EQ(r.passNames(), expected);
  ASSERT_EQ(r.lastTimings().size(), expected.size());
  for (const auto& t : r.lastTimings()) {
    EXPECT_GE(t.ms, 0.0);
    EXPECT_LT(t.ms, 10000.0);
  }
}

}  // namespace
}  // namespace gi
