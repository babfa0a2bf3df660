// The CPU reference renderer and the Vulkan renderer see the same geometry: for the same scene,
// camera and image size, the reference's primary-hit depth and normal equal the G-buffer's
// wherever both see a surface and the neighbourhood is smooth (away from silhouettes).
#include <gtest/gtest.h>

#include <cmath>

#include "gi/reference/reference.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

namespace ref = gi::reference;
using test::VulkanTest;

class ReferenceVsGBuffer : public VulkanTest {
 protected:
  // Renders `scene` both ways at 160x120, posed at `time` (Renderer::setTime against
  // Scene::animate), and compares depth (as view-space z) and normals.
  void compare(const Scene& scene, const std::string& what, double time = 0.0,
               double minCoverage = 0.25) {
    const uint32_t W = 160, H = 120;
    RenderSettings rs;
    rs.width = W;
    rs.height = H;
    Renderer renderer(ctx(), scene, rs);
    renderer.setTime(time);
    renderer.renderFrame();
    const ImageRGBA32F vkDepth = renderer.readTarget("depth");
    const ImageRGBA32F vkNormal = renderer.readTarget("normal");

    ref::Settings s;
    s.quantity = ref::Quantity::Depth;
    s.width = W;
    s.height = H;
    s.threads = 2;
    Scene posed = scene;
    posed.animate(time);
    const ref::Result r = ref::render(posed, s);
    // Same camera: the reference calls activeCamera with the same aspect.
    const glm::mat4 invProj = glm::inverse(renderer.camera().proj);
    EXPECT_EQ(renderer.camera().proj, r.camera.proj);
    EXPECT_EQ(renderer.camera().view, r.camera.view);

    auto refGeometry = [&](int x, int y) {
      return r.depth.pixels[(size_t(y) * W + x) * 4 + 3] > 0;
    };
    auto vkGeometry = [&](int x, int y) { return vkDepth.pixels[(size_t(y) * W + x) * 4] > 0; };
    auto refZ = [&](int x, int y) { return r.depth.pixels[(size_t(y) * W + x) * 4 + 1]; };
    auto refN = [&](int x, int y) {
      const float* n = &r.normal.pixels[(size_t(y) * W + x) * 4];
      return glm::vec3(n[0], n[1], n[2]);
    };

    int maskMismatch = 0, compared = 0, normalsCompared = 0;
    double worstZ = 0.0, worstNormal = 0.0;
    for (int y = 0; y < int(H); ++y) {
      for (int x = 0; x < int(W); ++x) {
        maskMismatch += refGeometry(x, y) != vkGeometry(x, y);
        if (x == 0 || y == 0 || x == int(W) - 1 || y == int(H) - 1) continue;
        // Interior of a surface: the 3x3 neighbourhood is geometry in both images and the
        // reference's depth varies by less than 2% across it (no silhouette nearby).
        bool smooth = true, flat = true;
        const float zc = refZ(x, y);
        for (int dy = -1; dy <= 1 && smooth; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            if (!refGeometry(x + dx, y + dy) || !vkGeometry(x + dx, y + dy) ||
                std::abs(refZ(x + dx, y + dy) - zc) > 0.02f * std::abs(zc)) {
              smooth = false;
              break;
            }
            flat = flat && glm::dot(refN(x + dx, y + dy), refN(x, y)) > 0.95f;
          }
        if (!smooth) continue;
        const size_t i = size_t(y) * W + x;
        const glm::vec2 uv((x + 0.5f) / W, (y + 0.5f) / H);
        const glm::vec4 v = invProj * glm::vec4(uv * 2.0f - 1.0f, vkDepth.pixels[i * 4], 1.0f);
        const float vkZ = v.z / v.w;
        // Depth: view-space z within 1e-4 relative (float reverse-Z depth and rasteriser
        // interpolation against a double-precision ray; measured worst cases on lavapipe:
        // 3.5e-7 default scene, 1.3e-6 bunny, 1.4e-5 2CylinderEngine).
        EXPECT_NEAR(vkZ, zc, 1e-4f * std::abs(zc)) << what << " pixel " << x << "," << y;
        worstZ = std::max(worstZ, double(std::abs(vkZ - zc) / std::abs(zc)));
        ++compared;
        if (!flat) continue;  // a crease: a pixel centre near the edge may pick either face
        // Normals: the same interpolated vertex normal (measured 1 - dot <= 2e-7; 1e-4 leaves
        // room for a half-float G-buffer).
        const glm::vec3 nv(vkNormal.pixels[i * 4], vkNormal.pixels[i * 4 + 1],
                           vkNormal.pixels[i * 4 + 2]);
        const float d = glm::dot(glm::normalize(nv), refN(x, y));
        EXPECT_GT(d, 1.0f - 1e-4f) << what << " normal at pixel " << x << "," << y;
        worstNormal = std::max(worstNormal, 1.0 - double(d));
        ++normalsCompared;
      }
    }
    // Geometry vs sky disagrees only along silhouettes (a pixel centre grazing an edge).
    EXPECT_LE(maskMismatch, int(W * H / 200)) << what;
    EXPECT_GT(compared, int(W * H * minCoverage)) << what;
    EXPECT_GT(normalsCompared, compared / 3) << what;
    std::printf(
        "%s: %d pixels compared, worst relative z difference %.3g, worst 1 - normal dot %.3g, "
        "%d mask mismatches\n",
        what.c_str(), compared, worstZ, worstNormal, maskMismatch);
  }
};

TEST_F(ReferenceVsGBuffer, DefaultScene) {
  compare(loadScene("default"), "default scene");
}

TEST_F(ReferenceVsGBuffer, LoadedModel) {
  compare(loadScene(test::assimpModel("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb")),
          "2CylinderEngine");
}

TEST_F(ReferenceVsGBuffer, BunnyOnPlane) {
  const std::string bunny = gi::test::modelAsset("stanford_bunny/bun_zipper.ply");
  compare(loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/bunny_on_plane.json"),
          "bunny on plane");
}

TEST_F(ReferenceVsGBuffer, SkinnedAndMorphedModelsAtATime) {
  // The reference poses vertices with the CPU twins of the skinning pass (gi/animation.h).
  compare(loadScene(test::assimpModel("glTF2/simple_skin/simple_skin.gltf")), "simple_skin", 0.75,
          0.05);
  compare(loadScene(test::assimpModel(
              "glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf")),
          "AnimatedMorphCube", 1.3, 0.05);
  const std::string path = gi::test::modelAsset("cesium_man/glTF/CesiumMan.gltf");
  compare(loadScene(path), "CesiumMan", 1.1, 0.03);
}

}  // namespace
}  // namespace gi
