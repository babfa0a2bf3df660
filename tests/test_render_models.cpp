// Real models load and render: geometry covers the image, everything is finite, and the
// BoxTextured texture is visible in the albedo channel.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

struct Coverage {
  size_t geometryPixels = 0, totalPixels = 0;
  bool finite = true;
};

class ModelRenderTest : public test::VulkanTest {
 protected:
  Coverage renderAndMeasure(const Scene& scene, ImageRGBA32F* albedoOut = nullptr) {
    RenderSettings rs;
    rs.width = 160;
    rs.height = 120;
    Renderer r(ctx(), scene, rs);
    r.renderFrame();
    Coverage c;
    ImageRGBA32F normal = r.readTarget("normal");
    for (size_t i = 0; i < normal.pixels.size(); i += 4)
      c.geometryPixels += normal.pixels[i + 3] > 0.5f;
    c.totalPixels = normal.pixels.size() / 4;
    for (const char* t : {"depth", "normal", "lit"})
      for (float v : r.readTarget(t).pixels) c.finite = c.finite && std::isfinite(v);
    if (albedoOut) *albedoOut = r.readTarget("albedo");
    return c;
  }
  void expectRenders(const std::string& path) {
    Scene scene = loadScene(path);
    ASSERT_GT(scene.triangleCount(), 0u);
    Coverage c = renderAndMeasure(scene);
    EXPECT_TRUE(c.finite) << path;
    // A framed model covers a real part of the image, not a speck and not everything.
    EXPECT_GT(c.geometryPixels, c.totalPixels / 50) << path;
  }
};

TEST_F(ModelRenderTest, TwoCylinderEngine) {
  expectRenders(test::assimpModel("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"));
}

TEST_F(ModelRenderTest, Fox) {
  const std::string path = gi::test::modelAsset("fox/glTF-Binary/Fox.glb");
  expectRenders(path);
}

TEST_F(ModelRenderTest, CesiumMan) {
  const std::string path = gi::test::modelAsset("cesium_man/glTF/CesiumMan.gltf");
  expectRenders(path);
}

TEST_F(ModelRenderTest, CornellBoxObj) {
  const std::string path = gi::test::modelAsset("cornell_box/cornell_box.obj");
  expectRenders(path);
}

TEST_F(ModelRenderTest, StanfordBunnyPly) {
  const std::string path = gi::test::modelAsset("stanford_bunny/bun_zipper.ply");
  expectRenders(path);
}

TEST_F(ModelRenderTest, DefaultScene) {
  expectRenders("default");
}

TEST_F(ModelRenderTest, BoxTexturedShowsItsTexture) {
  Scene scene = loadScene(test::assimpModel("glTF2/BoxTextured-glTF/BoxTextured.gltf"));
  ASSERT_FALSE(scene.textures.empty());
  ImageRGBA32F textured, plain;
  Coverage c = renderAndMeasure(scene, &textured);
  ASSERT_GT(c.geometryPixels, 500u);
  for (Material& m : scene.materials) m.baseColorTexture = -1;
  renderAndMeasure(scene, &plain);
  // Where the box is, the textured albedo differs from the untextured one in most pixels and
  // shows many colours (the logo), while the untextured box is one flat colour.
  size_t differing = 0;
  std::set<int> texturedColours, plainColours;
  for (size_t i = 0; i < textured.pixels.size(); i += 4) {
    if (plain.pixels[i + 3] == 0.0f) continue;
    float d = std::abs(textured.pixels[i] - plain.pixels[i]) +
              std::abs(textured.pixels[i + 1] - plain.pixels[i + 1]) +
              std::abs(textured.pixels[i + 2] - plain.pixels[i + 2]);
    differing += d > 0.05f;
    auto key = [](const float* p) {
      return int(p[0] * 31) << 10 | int(p[1] * 31) << 5 | int(p[2] * 31);
    };
    texturedColours.insert(key(&textured.pixels[i]));
    plainColours.insert(key(&plain.pixels[i]));
  }
  EXPECT_GT(differing, c.geometryPixels / 4);
  EXPECT_GT(texturedColours.size(), 10u);
  EXPECT_LE(plainColours.size(), 2u);
}

}  // namespace
}  // namespace gi

namespace gi {
namespace {

// Frustum culling of the draws (RenderSettings::cullDraws) gives the same image bit for bit:
// the demo courtyard at two times (skinned characters walking, an orbiting spot, a wandering
// point light's six cube faces, the sun) and the animated scene, and it skips draws: in the
// courtyard over a third of the instance draws (most of a cube face's instances lie outside it).
TEST_F(ModelRenderTest, FrustumCullingDrawsLessAndChangesNoPixel) {
  for (const char* file : {"demo.json", "animated.json"}) {
    const Scene scene = loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/" + file);
    for (double time : {0.0, 7.3}) {
      SCOPED_TRACE(std::string(file) + " at " + std::to_string(time));
      RenderSettings rs;
      rs.width = 160;
      rs.height = 90;
      rs.view = "lit";
      rs.keepForReadback = {"depth", "shadow_maps"};
      Renderer culled(ctx(), scene, rs);
      rs.cullDraws = false;
      Renderer all(ctx(), scene, rs);
      for (Renderer* r : {&culled, &all}) {
        r->setTime(time);
        r->renderFrame();
      }
      for (const char* t : {"lit", "depth", "shadow_maps"})
        EXPECT_EQ(culled.readTarget(t).pixels, all.readTarget(t).pixels) << t;
      const Renderer::DrawCounts c = culled.lastFrameDraws(), a = all.lastFrameDraws();
      EXPECT_EQ(a.culled, 0u);
      EXPECT_EQ(c.drawn + c.culled, a.drawn) << "the same draws considered";
      // The courtyard spreads its instances around its lights (measured: 89-93 of 171); the
      // animated scene's few instances sit together in every view.
      if (std::string(file) == "demo.json") {
        EXPECT_GT(c.culled, a.drawn / 3) << "culled " << c.culled << " of " << a.drawn;
      }
      std::printf("%s t=%.1f: %llu of %llu instance draws culled\n", file, time,
                  static_cast<unsigned long long>(c.culled),
                  static_cast<unsigned long long>(a.drawn));
    }
  }
}

}  // namespace
}  // namespace gi
