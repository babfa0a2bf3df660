// SSDO over time (issue 12). On the animated scene (assets/scenes/animated.json) the darkening
// and the bounce that the walking Fox adds follow it frame by frame, and the floor it left
// returns exactly to its value without the Fox. On a slow camera path through a static scene
// the output does not flicker: its change per frame after reprojection stays below a stated
// bound, which the same metric shows broken by the screen-fixed 4x4 pattern without the blur
// and by sample sets that change every frame; where the camera stops, frames are identical.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "effect_fixture.h"
#include "gi/effect_config.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "quad_scene.h"
#include "ssdo_frames.h"
#include "test_support.h"

namespace gi {
namespace {

constexpr uint32_t kW = 160, kH = 120;

class SsdoDynamicTest : public test::EffectTest {
 protected:
  std::string effectName() const override { return "ssdo"; }
  RenderSettings settingsFor(const Scene& scene, const std::vector<std::string>& sets) const {
    return EffectTest::settingsFor(scene, sets, kW, kH);
  }
  static test::SsdoFrame grab(Renderer& r) {
    r.renderFrame();
    return test::SsdoFrame(test::ssdoAmbientRadiance(r), r.readTarget("indirect"),
                           r.readTarget("depth"), r.camera());
  }
};

// ---- the walking Fox ------------------------------------------------------------------------

// The Fox of animated.json walks a circle of radius 0.8 every 7 s (~0.72 m/s). Six frames
// 0.5 s apart (~26 degrees, 0.36 m, ~9 pixels each at 160x120) through one renderer. The reference
// at every frame is the same scene at the same time without the Fox's meshes (a second renderer):
// the ambient term depends only on the geometry and the sky, so every difference on the floor is
// the Fox's. Per frame:
// - the floor darkened by the Fox (ambient below the Fox-less value by more than 2%) is there
//   (>= 20 pixels) and its centroid (weighted by the darkening) lies within 6 pixels (~0.2 m
//   here) of the Fox's footprint (the centroid of its visible surface dropped to the floor,
//   projected), and it moved by the footprint's displacement since the first frame within
//   4 pixels (measured: see the printout);
// - the Fox's bounce (indirect above the Fox-less value) likewise, within 8 pixels (the bounce
//   comes from the Fox's lit side only, so it sits off its footprint's centre);
// - every floor pixel whose blur footprint (5x5 pixels) is farther than 2.2 R from the visible
//   Fox (a sample reaches R, an occluder counts within R in front of it) has exactly the
//   Fox-less ambient, and, where the Fox-less indirect is 0, an indirect of 0: the floor the
//   Fox darkened in an earlier frame (counted: > 20 pixel-frames over the run, measured 530)
//   returned to the unoccluded value, nothing lingers.
// Measured: darkening 1.6..3.2 pixels off the footprint, its motion 0..1.5 pixels off the
// footprint's; bounce 0.7..3.7 pixels off. A one-frame lag (a stale input) would be ~9 pixels.
TEST_F(SsdoDynamicTest, ShadowAndBounceFollowTheWalkingFoxFrameByFrame) {
  for (const char* m : {"glTF2/simple_skin/simple_skin.gltf",
                        "glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf"})
    if (!std::filesystem::exists(test::assimpModel(m))) GTEST_SKIP() << m << " absent";
  const Scene withFox = loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/animated.json");
  int foxNode = -1;
  for (size_t n = 0; n < withFox.nodes.size(); ++n)
    if (withFox.nodes[n].name == "Fox") foxNode = int(n);
  ASSERT_GE(foxNode, 0);
  Scene noFox = withFox;
  std::vector<int> stack = {foxNode};
  while (!stack.empty()) {
    Node& n = noFox.nodes[size_t(stack.back())];
    stack.pop_back();
    n.meshes.clear();
    stack.insert(stack.end(), n.children.begin(), n.children.end());
  }
  const float R = 0.5f;
  // One layer (the bounds above were measured with it) and the default two: with the Fox's
  // back faces as a second layer, samples behind its body are no longer blocked, so about half
  // as many floor pixels darken (the contact shadow under it) and their centroid is noisier:
  // 8 / 6 pixels off the footprint / its motion there (measured 1.2..5.6 / 0..4.4), still
  // below the ~9 of a one-frame lag.
  for (const int layers : {1, 2}) {
    SCOPED_TRACE("layers " + std::to_string(layers));
    const std::vector<std::string> sets = {"ssdo.radius=0.5",
                                           "ssdo.layers=" + std::to_string(layers)};
    Renderer a(ctx(), withFox, settingsFor(withFox, sets), &registry);
    Renderer b(ctx(), noFox, settingsFor(noFox, sets), &registry);

    const int frames = 6;  // at 3 s the Fox walks behind the morphing cube
    const double dt = 0.5;
    std::vector<bool> darkenedBefore(size_t(kW * kH), false);
    glm::vec2 firstDark(0.0f), firstFoot(0.0f);
    int returned = 0;
    for (int k = 0; k < frames; ++k) {
      SCOPED_TRACE("frame " + std::to_string(k));
      a.setTime(k * dt);
      b.setTime(k * dt);
      const test::SsdoFrame fa = grab(a), fb = grab(b);
      ASSERT_TRUE(test::finite(fa.ambient) && test::finite(fa.indirect));
      // The Fox's visible surface: depth in front of the Fox-less one (reverse-Z: larger).
      std::vector<glm::vec3> foxPoints;
      glm::vec3 foxMean(0.0f);
      for (int y = 0; y < fa.h; ++y)
        for (int x = 0; x < fa.w; ++x)
          if (fa.depthAt(x, y) > fb.depthAt(x, y) * (1.0f + 1e-4f) + 1e-7f) {
            foxPoints.push_back(fa.worldAt(x, y));
            foxMean += foxPoints.back();
          }
      ASSERT_GT(foxPoints.size(), 100u) << "the Fox must be in view";
      foxMean /= float(foxPoints.size());
      const glm::vec2 foot = fa.project({foxMean.x, 0.0f, foxMean.z});

      // Per pixel, the distance of its surface to the nearest visible Fox point (0 on the Fox).
      std::vector<float> nearest(size_t(kW * kH), 0.0f);
      for (int y = 0; y < fa.h; ++y)
        for (int x = 0; x < fa.w; ++x) {
          if (fa.sky(x, y)) {
            nearest[size_t(y) * kW + size_t(x)] = 1e9f;
            continue;
          }
          const glm::vec3 p = fa.worldAt(x, y);
          float d = 1e9f;
          for (const glm::vec3& q : foxPoints) d = std::min(d, glm::length(q - p));
          nearest[size_t(y) * kW + size_t(x)] = d;
        }
      // Far: every pixel of the 5x5 block the blur (radius 2, x then y) gathers is more than
      // 2.2 R from the Fox (a sample reaches R; an occluder counts within R of it in view depth,
      // up to 1.1 R along an oblique ray).
      auto far = [&](int x, int y) {
        for (int j = std::max(0, y - 2); j <= std::min(fa.h - 1, y + 2); ++j)
          for (int i = std::max(0, x - 2); i <= std::min(fa.w - 1, x + 2); ++i)
            if (nearest[size_t(j) * kW + size_t(i)] <= 2.2f * R) return false;
        return true;
      };

      glm::dvec3 dark(0.0), bounce(0.0);  // (sum w x, sum w y, sum w)
      int nDark = 0, nBounce = 0, farFloor = 0, farUnlit = 0;
      for (int y = 0; y < fa.h; ++y)
        for (int x = 0; x < fa.w; ++x) {
          if (fa.sky(x, y) || fa.depthAt(x, y) != fb.depthAt(x, y)) continue;
          const glm::vec3 p = fa.worldAt(x, y);
          if (std::abs(p.y) > 1e-2f) continue;  // the floor only
          const size_t i = size_t(y) * kW + size_t(x);
          const float open = fb.sum(fb.ambient, x, y), dDark = open - fa.sum(fa.ambient, x, y);
          const float dBounce = fa.sum(fa.indirect, x, y) - fb.sum(fb.indirect, x, y);
          if (dDark > 0.02f * open) {
            dark += glm::dvec3(x * dDark, y * dDark, dDark);
            ++nDark;
            darkenedBefore[i] = true;
          }
          if (dBounce > 1e-4f) {
            bounce += glm::dvec3(x * dBounce, y * dBounce, dBounce);
            ++nBounce;
          }
          if (!far(x, y)) continue;
          ++farFloor;
          ASSERT_EQ(fa.sum(fa.ambient, x, y), open) << x << "," << y << " far from the Fox";
          if (fb.sum(fb.indirect, x, y) == 0.0f) {
            ++farUnlit;
            ASSERT_EQ(fa.sum(fa.indirect, x, y), 0.0f) << x << "," << y << " far from the Fox";
          }
          if (darkenedBefore[i] && !(dDark > 0.02f * open)) ++returned;
        }
      ASSERT_GE(nDark, 20);
      ASSERT_GE(nBounce, 20);
      ASSERT_GT(farFloor, 1000);
      ASSERT_GT(farUnlit, 1000);
      const glm::vec2 cDark(dark.x / dark.z, dark.y / dark.z),
          cBounce(bounce.x / bounce.z, bounce.y / bounce.z);
      if (k == 0) {
        firstDark = cDark;
        firstFoot = foot;
      }
      const float moved = glm::length((cDark - firstDark) - (foot - firstFoot));
      std::printf(
          "t %.1f: footprint (%.1f, %.1f); darkened %d px at (%.1f, %.1f), off by %.1f px, moved "
          "off by %.1f px; bounce %d px at (%.1f, %.1f), off by %.1f px\n",
          k * dt, foot.x, foot.y, nDark, cDark.x, cDark.y, glm::length(cDark - foot), moved,
          nBounce, cBounce.x, cBounce.y, glm::length(cBounce - foot));
      EXPECT_LT(glm::length(cDark - foot), layers == 1 ? 6.0f : 8.0f);
      EXPECT_LT(moved, layers == 1 ? 4.0f : 6.0f);
      EXPECT_LT(glm::length(cBounce - foot), 8.0f);
    }
    std::printf(
        "layers %d: floor pixels darkened earlier and back at the unoccluded value: %d "
        "(pixel-frames)\n",
        layers, returned);
    EXPECT_GT(returned, 20);
  }
}

// ---- flicker on a camera path -----------------------------------------------------------------

// The default room (static: its time stays 0; the camera 4.9 from its back wall, 2.9 from its
// opening). The camera slides 0.6 to its right over 56 frames without turning (0.4 pixel per
// frame at the back wall, 0.6 at the opening, at 160x120), then stops for 8 frames.
std::vector<CameraView> cameraPath(const CameraView& start, int moving, int stopped) {
  const glm::mat4 inv = glm::inverse(start.view);
  const glm::vec3 eye(inv[3]), right = glm::normalize(glm::vec3(inv[0])),
                               forward = -glm::normalize(glm::vec3(inv[2]));
  std::vector<CameraView> path;
  for (int k = 0; k < moving + stopped; ++k) {
    CameraView c = start;
    c.position = eye + right * (0.6f * float(std::min(k, moving - 1)) / float(moving - 1));
    c.view = glm::lookAt(c.position, c.position + forward, glm::vec3(0, 1, 0));
    path.push_back(c);
  }
  return path;
}

// Flicker (test::flicker, ssdo_frames.h): the mean over consecutive frames of the mean absolute
// change of the ambient term after reprojection, relative to its mean. For a term that belongs
// to the surface the reprojected change is only resampling (bilinear) and the slow change of
// what the screen shows; a screen-fixed pattern sliding over the surfaces, or samples that
// change every frame, make it jump. Bound test::kFlickerBound = 1.5%: measured 0.71% (worst pair
// 1.04%; one layer: 0.83%) with the blur, which averages every 4x4 pattern phase, so a surface
// point's value barely depends on where it falls in the pattern; 5.4% without the blur (the next
// test: a point changes sample set whenever it changes pixel). Where the camera stops the frames
// are identical: SSDO keeps no temporal state and draws no per-frame random numbers (per-frame
// sample sets give 1.15% at a still camera: the next test).
// The bounce term's own flicker bound: its screen-space senders change as the pattern slides
// over the surfaces (measured 0.193; it is 4% of the ambient term, so ~0.8% of the sum).
constexpr double kBounceFlickerBound = 0.25;

TEST_F(SsdoDynamicTest, CameraPathOverAStaticSceneDoesNotFlicker) {
  const Scene scene = makeDefaultScene();
  Renderer r(ctx(), scene, settingsFor(scene, {}), &registry);
  const std::vector<CameraView> path = cameraPath(r.camera(), 56, 8);
  std::vector<test::SsdoFrame> frames;
  for (const CameraView& c : path) {
    r.setCameraOverride(c);
    frames.push_back(grab(r));
    ASSERT_TRUE(test::finite(frames.back().ambient));
  }
  const test::Flicker f = test::flicker({frames.begin(), frames.begin() + 56});
  std::printf("flicker over 55 moving frames: %.4f (worst pair %.4f, %.0f%% of pixels compared)\n",
              f.mean, f.worst, 100.0 * f.coverage);
  EXPECT_GT(f.coverage, 0.5);
  EXPECT_LT(f.mean, test::kFlickerBound);
  // The bounce (`indirect`) under the same metric: fewer samples find a sender than an
  // occluder, so it is the noisier term.
  std::vector<test::SsdoFrame> bounce;
  for (size_t k = 0; k < 56; ++k)
    bounce.emplace_back(frames[k].indirect, frames[k].indirect, frames[k].depth, frames[k].camera);
  const test::Flicker fb = test::flicker(bounce);
  double bounceSum = 0.0, ambientSum = 0.0;
  for (size_t k = 0; k < 56; ++k)
    for (int y = 0; y < frames[k].h; ++y)
      for (int x = 0; x < frames[k].w; ++x) {
        bounceSum += frames[k].sum(frames[k].indirect, x, y);
        ambientSum += frames[k].sum(frames[k].ambient, x, y);
      }
  std::printf(
      "bounce flicker over 55 moving frames: %.4f (worst pair %.4f, %.0f%% compared); "
      "the bounce is %.3f of the ambient term\n",
      fb.mean, fb.worst, 100.0 * fb.coverage, bounceSum / ambientSum);
  EXPECT_GT(fb.coverage, 0.5);
  EXPECT_LT(fb.mean, kBounceFlickerBound);
  // Both terms together (the bounce per unit albedo added to the ambient radiance: an upper
  // bound on what the albedo-weighted sum shows) stay within the ambient term's bound.
  std::vector<test::SsdoFrame> both;
  for (size_t k = 0; k < 56; ++k) {
    ImageRGBA32F sum = frames[k].ambient;
    for (size_t i = 0; i < sum.pixels.size(); ++i)
      if (i % 4 != 3) sum.pixels[i] += frames[k].indirect.pixels[i];
    both.emplace_back(sum, frames[k].indirect, frames[k].depth, frames[k].camera);
  }
  const test::Flicker fs = test::flicker(both);
  std::printf("ambient + bounce flicker: %.4f (worst pair %.4f)\n", fs.mean, fs.worst);
  EXPECT_LT(fs.mean, test::kFlickerBound);
  // Frame 55 is the last move's; 56..63 keep its camera.
  for (size_t k = 56; k < frames.size(); ++k) {
    ASSERT_EQ(frames[k].ambient.pixels, frames[55].ambient.pixels) << "frame " << k;
    ASSERT_EQ(frames[k].indirect.pixels, frames[55].indirect.pixels) << "frame " << k;
  }
}

// The criteria can fail: without the blur the screen-fixed pattern slides over the surfaces
// (16 frames of the path: > 2x the bound, measured 5.4%); with the sample sets changed every
// frame (pattern_sets cycling 16, 15, 13, 11: other Hammersley sets each frame, as a per-frame
// random rotation would give) a still camera sees a different image each frame (8 frames:
// > 0.5x the bound, measured 1.15%, where SSDO's own still frames are identical).
TEST_F(SsdoDynamicTest, FlickerMetricCatchesASlidingPatternAndPerFrameSampleSets) {
  const Scene scene = makeDefaultScene();
  const int n = 16;
  {
    Renderer r(ctx(), scene, settingsFor(scene, {"ssdo.blur_radius=0"}), &registry);
    const std::vector<CameraView> path = cameraPath(r.camera(), 56, 0);
    std::vector<test::SsdoFrame> frames;
    for (int k = 0; k < n; ++k) {
      r.setCameraOverride(path[size_t(k)]);
      frames.push_back(grab(r));
    }
    const test::Flicker f = test::flicker(frames);
    std::printf("no blur: flicker %.4f (worst pair %.4f)\n", f.mean, f.worst);
    EXPECT_GT(f.mean, 2.0 * test::kFlickerBound);
  }
  {
    // A still camera: SSDO's own frames are identical there (asserted above).
    Renderer r(ctx(), scene, settingsFor(scene, {}), &registry);
    const int cycle[4] = {16, 15, 13, 11};
    std::vector<test::SsdoFrame> frames;
    for (int k = 0; k < 8; ++k) {
      SettingValues v = r.settings().effects.front().settings;
      v.set("pattern_sets", cycle[k % 4], "test");
      r.setEffectSettings("ssdo", v);
      ASSERT_FALSE(r.graphRecompiledByLastChange());  // a uniform, as a per-frame rotation
      frames.push_back(grab(r));
    }
    const test::Flicker f = test::flicker(frames);
    std::printf("sample sets changing every frame, still camera: flicker %.4f (worst pair %.4f)\n",
                f.mean, f.worst);
    EXPECT_GT(f.mean, 0.5 * test::kFlickerBound);
    EXPECT_GT(f.worst, 0.0);
  }
}

// The metric itself: a still image sequence reads 0; the same with i.i.d. multiplicative noise
// of +-a per pixel and frame reads E|u - v| = 2a/3 for u, v uniform in [-a, a] (a = 3%: 2%).
TEST(SsdoFlickerMetric, ZeroForAStillSequenceAndTheNoiseAmplitudeForNoise) {
  CameraView c;
  c.view = glm::lookAt(glm::vec3(0, 0, 3), glm::vec3(0), glm::vec3(0, 1, 0));
  c.proj = perspectiveReverseZ(glm::radians(45.0f), 4.0f / 3.0f, 0.1f, 100.0f);
  // A plane z = 0 facing the camera filling the view: depth from the projection.
  ImageRGBA32F depth{int(kW), int(kH), std::vector<float>(size_t(kW * kH) * 4, 0.0f)};
  const glm::vec4 clip = c.proj * c.view * glm::vec4(0, 0, 0, 1);
  for (size_t i = 0; i < size_t(kW * kH); ++i) depth.pixels[i * 4] = clip.z / clip.w;
  ImageRGBA32F ambient{int(kW), int(kH), std::vector<float>(size_t(kW * kH) * 4, 0.5f)};
  std::vector<test::SsdoFrame> still(4, test::SsdoFrame(ambient, ambient, depth, c));
  const test::Flicker zero = test::flicker(still);
  EXPECT_EQ(zero.mean, 0.0);
  EXPECT_GT(zero.coverage, 0.9);
  uint32_t state = 12345u;
  auto uniform = [&] {  // xorshift32 in [-1, 1]
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return float(state) / 4294967295.0f * 2.0f - 1.0f;
  };
  std::vector<test::SsdoFrame> noisy = still;
  for (test::SsdoFrame& f : noisy)
    for (size_t i = 0; i < f.ambient.pixels.size(); i += 4) {
      const float v = 0.5f * (1.0f + 0.03f * uniform());
      for (int ch = 0; ch < 3; ++ch) f.ambient.pixels[i + size_t(ch)] = v;
    }
  const test::Flicker f = test::flicker(noisy);
  std::printf("synthetic noise +-3%%: flicker %.4f\n", f.mean);
  EXPECT_NEAR(f.mean, 0.02, 0.001);
  EXPECT_GT(f.mean, test::kFlickerBound);
}

}  // namespace
}  // namespace gi
