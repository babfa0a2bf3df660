// Shadow maps that cost only what changed (RenderSettings::cacheShadows, render/shadow_cache.h):
// the texels a dynamic caster may cover, and, on an animated scene (a skinned figure, an
// orbiting box, a static box that jumps once, two still lights and a moving one), frames that
// are the same bit for bit as drawing every map whole, with the cached maps really reused and a
// moved static object's shadow updated in the frame it moves.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "render/shadow_cache.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using shadow_cache::Box;
using test::VulkanTest;

const VkRect2D kView{{200, 100}, {100, 100}};  // a view's tile in a larger atlas

bool equal(const std::optional<VkRect2D>& r, int x, int y, unsigned w, unsigned h) {
  return r && r->offset.x == x && r->offset.y == y && r->extent.width == w && r->extent.height == h;
}

TEST(ShadowCacheTexels, AnOrthographicBoxCoversItsProjectionAndOneTexelMore) {
  // Clip = world for x, y in [-1, 1]; z = 0.5 lies between the far (0) and near (w) planes.
  const glm::mat4 clip(1.0f);
  const Box box{{-0.5f, 0.0f, 0.5f}, {0.0f, 0.5f, 0.5f}};
  // x: (-0.5 + 1) / 2 x 100 = 25 .. 50, y: 50 .. 75; widened by one texel, offset by the tile.
  // With the second box, x: 25 .. 95, y: 5 .. 75.
  EXPECT_TRUE(
      equal(shadow_cache::coveredTexels(clip, kView, std::vector<Box>{box}), 224, 149, 27, 27));
  // Two boxes: the bounds of both.
  const Box other{{0.8f, -0.9f, 0.5f}, {0.9f, -0.8f, 0.5f}};
  EXPECT_TRUE(equal(shadow_cache::coveredTexels(clip, kView, std::vector<Box>{box, other}), 224,
                    104, 72, 72));
}

TEST(ShadowCacheTexels, NothingOutsideTheViewAndAllOfItBehindAPerspectiveEye) {
  const glm::mat4 clip(1.0f);
  EXPECT_FALSE(
      shadow_cache::coveredTexels(clip, kView, std::vector<Box>{{{1.5f, 0, 0.5f}, {2, 1, 0.5f}}}));
  EXPECT_FALSE(shadow_cache::coveredTexels(clip, kView, std::vector<Box>{}));
  // Clipped at the edge: only texels inside the tile.
  EXPECT_TRUE(equal(shadow_cache::coveredTexels(
                        clip, kView, std::vector<Box>{{{0.9f, -0.1f, 0.5f}, {3, 0.1f, 0.5f}}}),
                    294, 144, 6, 12));
  // A box reaching behind a perspective eye (w <= 0 at some corner) may cover any texel.
  const glm::mat4 persp = glm::perspective(1.0f, 1.0f, 0.1f, 10.0f);
  EXPECT_TRUE(equal(shadow_cache::coveredTexels(
                        persp, kView, std::vector<Box>{{{-0.1f, -0.1f, -2}, {0.1f, 0.1f, 1}}}),
                    200, 100, 100, 100));
}

TEST(ShadowCacheTexels, UniteKeepsBothAndAnAbsentOneChangesNothing) {
  const VkRect2D a{{0, 0}, {4, 4}}, b{{10, 2}, {2, 8}};
  EXPECT_TRUE(equal(shadow_cache::unite(a, b), 0, 0, 12, 10));
  EXPECT_TRUE(equal(shadow_cache::unite(std::nullopt, b), 10, 2, 2, 8));
  EXPECT_FALSE(shadow_cache::unite(std::nullopt, std::nullopt));
}

// Plane, a still box, a box orbiting the centre, a box that stands still until t = 0.35 and then
// jumps 2.8 m (its clip lasts 10 s) (a "static" object that moves once), the skinned CesiumMan
// walking on the spot; a still sun and point light, an orbiting spot light; all three cast shadows.
Scene animatedScene() {
  const std::string dir = test::makeTempDir("shadow-cache");
  const std::string path = dir + "/scene.json";
  std::ofstream(path) << R"({
    "models": [
      {"primitive": "plane", "size": 6, "material": {"base_color": [0.8, 0.8, 0.8]}},
      {"primitive": "box", "size": 0.5, "translation": [-1.2, 0.6, 0.2]},
      {"primitive": "box", "size": 0.4, "translation": [1.2, 0.5, 0],
       "animation": {"orbit": {"center": [0, 0, 0], "axis": [0, 1, 0], "period": 3}}},
      {"primitive": "box", "size": 0.45, "translation": [-1.0, 0.4, -1.6],
       "animation": {"translation": {"times": [0, 0.35, 10],
                                     "values": [[-1.0, 0.4, -1.6], [0.2, 0.4, 1.2], [0.2, 0.4, 1.2]],
                                     "interpolation": "step"}}},
      {"file": ")" + std::string(GI_SOURCE_DIR) +
                             R"(/assets/models/cesium_man/glTF/CesiumMan.gltf",
       "translation": [0, 0, -0.6]}],
    "camera": {"position": [0, 5.5, 3.5], "target": [0, 0, 0], "yfov_deg": 60},
    "lights": [
      {"type": "directional", "direction": [1, -2, 0.5], "intensity": 2, "casts_shadows": true},
      {"type": "point", "position": [0.3, 2.2, 0.6], "intensity": 8, "casts_shadows": true},
      {"type": "spot", "position": [0, 3, 2], "direction": [0, -3, -2], "intensity": 20,
       "outer_cone_deg": 40, "inner_cone_deg": 30, "casts_shadows": true,
       "animation": {"orbit": {"center": [0, 0, 0], "axis": [0, 1, 0], "period": 5}}}],
    "environment": {"type": "constant", "color": [1, 1, 1], "intensity": 0.05}})";
  return loadScene(path);
}

class ShadowCacheTest : public VulkanTest {};

// The lit image of a small frame with 256-texel shadow maps.
RenderSettings smallLitFrame() {
  RenderSettings rs;
  rs.width = 160;
  rs.height = 120;
  rs.view = "lit";
  rs.shadowMapSize = 256;
  return rs;
}

TEST_F(ShadowCacheTest, FramesEqualDrawingEveryMapWholeAndReuseTheStillLightsMaps) {
  const Scene scene = animatedScene();
  RenderSettings rs = smallLitFrame();
  rs.keepForReadback = {"shadow_maps"};
  RenderSettings whole = rs;
  whole.cacheShadows = false;
  Renderer cached(ctx(), scene, rs), drawn(ctx(), scene, whole);
  std::vector<ImageRGBA32F> frames;
  for (int f = 0; f < 7; ++f) {
    const double t = 0.1 * f;
    for (Renderer* r : {&cached, &drawn}) {
      r->setTime(t);
      r->renderFrame();
    }
    SCOPED_TRACE("frame " + std::to_string(f) + " at t = " + std::to_string(t));
    const ImageRGBA32F a = cached.readTarget("lit"), b = drawn.readTarget("lit");
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    size_t differing = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) differing += a.pixels[i] != b.pixels[i];
    EXPECT_EQ(differing, 0u) << "cached shadow maps are not the maps drawn whole";
    EXPECT_EQ(cached.readTarget("shadow_maps").pixels, drawn.readTarget("shadow_maps").pixels);
    frames.push_back(a);

    const Renderer::DrawCounts c = cached.lastFrameDraws(), d = drawn.lastFrameDraws();
    EXPECT_EQ(d.shadowMapsDrawn, 3u);
    EXPECT_EQ(d.shadowMapsCached, 0u);
    // 0: first frame; 1: the orbiting box moved (static casters changed); 2: the still
    // lights' caches are built; 3: reused; 4: the jumping box moved; 5: rebuilt; 6: reused.
    // The spot light moves every frame: always drawn whole.
    const bool reuse = f == 3 || f == 6;
    EXPECT_EQ(c.shadowMapsCached, reuse ? 2u : 0u);
    EXPECT_EQ(c.shadowMapsDrawn, reuse ? 1u : 3u);
    if (reuse) {
      EXPECT_LT(c.drawn, d.drawn) << "reused maps should draw only dynamic casters";
    }
  }
  // The ground at (-0.6, 0, -1.35) lies in the jumping box's sun shadow before the jump (the
  // ray towards the sun meets the box at t = 0.3) and in view; it is lit in the frame the box
  // jumped: a stale cache would have kept the shadow there.
  const CameraView& cam = cached.camera();
  const glm::vec4 clip = cam.proj * cam.view * glm::vec4(-0.6f, 0.0f, -1.35f, 1.0f);
  const int x = int((clip.x / clip.w * 0.5f + 0.5f) * float(rs.width));
  const int y = int((clip.y / clip.w * 0.5f + 0.5f) * float(rs.height));
  ASSERT_TRUE(x >= 0 && x < int(rs.width) && y >= 0 && y < int(rs.height));
  const size_t i = (size_t(y) * rs.width + size_t(x)) * 4 + 1;
  EXPECT_GT(frames[4].pixels[i], 2.0f * frames[3].pixels[i]) << "pixel " << x << ", " << y;
}

// engine.shadow_update_period 3: the orbiting spot light's map (slot 2) is drawn whole on every
// third frame and kept with the views it was drawn with in between. On the frames it is drawn
// the image is the exact one bit for bit; in between it differs a little (its shadows lag the
// light by one or two frames of its orbit) and stays finite; the still lights' maps come from
// their caches throughout.
TEST_F(ShadowCacheTest, AMovingLightsMapIsDrawnEveryNthFrameAndKeptInBetween) {
  const Scene scene = animatedScene();
  const RenderSettings rs = smallLitFrame();
  RenderSettings amortised = rs;
  amortised.shadowUpdatePeriod = 3;
  Renderer exact(ctx(), scene, rs), lagging(ctx(), scene, amortised);
  int drawnFrames = 0, keptFrames = 0;
  for (int f = 0; f < 11; ++f) {
    const double t = 0.5 + 0.05 * f;  // after the box's jump; the orbiting box moves each frame
    for (Renderer* r : {&exact, &lagging}) {
      r->setTime(t);
      r->renderFrame();
    }
    if (f < 2) continue;  // the first frame and the orbiting box's first move draw every map
    SCOPED_TRACE("frame " + std::to_string(f));
    const Renderer::DrawCounts c = lagging.lastFrameDraws();
    ASSERT_EQ(c.shadowMapsDrawn + c.shadowMapsCached, 3u);
    ASSERT_LE(c.shadowMapsDrawn, 1u) << "only the moving spot light is ever drawn whole";
    const ImageRGBA32F a = lagging.readTarget("lit"), b = exact.readTarget("lit");
    double diff = 0.0, sum = 0.0;
    size_t differing = 0;
    for (size_t i = 0; i < a.pixels.size(); i += 4)
      for (int ch = 0; ch < 3; ++ch) {
        ASSERT_TRUE(std::isfinite(a.pixels[i + ch]));
        diff += std::abs(a.pixels[i + ch] - b.pixels[i + ch]);
        sum += std::abs(b.pixels[i + ch]);
        differing += a.pixels[i + ch] != b.pixels[i + ch];
      }
    if (c.shadowMapsDrawn == 1) {
      ++drawnFrames;
      EXPECT_EQ(differing, 0u) << "drawn whole, the map is the exact one";
    } else {
      ++keptFrames;
      EXPECT_GT(differing, 0u) << "a kept map lags the moving light";
      // Measured 0.0018 one frame behind, 0.0034 two; a kept map read with today's views
      // instead of the ones it was drawn with gives 0.0029 and 0.0058-0.0068.
      EXPECT_LT(diff / sum, 0.0045) << "relative L1 difference from the exact frame";
    }
  }
  EXPECT_EQ(drawnFrames, 3);  // frames 2..10: one in three
  EXPECT_EQ(keptFrames, 6);
}

}  // namespace
}  // namespace gi
