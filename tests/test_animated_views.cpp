// Animated lights and cameras: Renderer::setTime re-plans the light records and shadow views
// and moves the camera, in the same renderer (no rebuild): a rotating sun moves the box's
// shadow to where the analytic projection puts it, and a moving camera produces the motion
// vectors of its displacement.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <glm/gtc/quaternion.hpp>

#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

class AnimatedViewTest : public VulkanTest {};

// Plane y = 0, a 0.5 box floating at y = 1, camera above, one sun along `sunDir`.
Scene boxScene() {
  const std::string path = test::makeTempDir("animated-views") + "/scene.json";
  std::ofstream(path) << R"({
    "models": [
      {"primitive": "plane", "size": 5, "material": {"base_color": [0.8, 0.8, 0.8]}},
      {"primitive": "box", "size": 0.5, "translation": [0, 1, 0]}],
    "camera": {"position": [0, 5, 0], "target": [0, 0, 0], "up": [0, 0, -1], "yfov_deg": 60},
    "lights": [{"type": "directional", "direction": [1, -2, 0], "intensity": 3}],
    "environment": {"type": "constant", "color": [1, 1, 1], "intensity": 0.02}})";
  return loadScene(path);
}

// Gives a root node (set by a matrix) the equivalent TRS, so animation channels can drive it.
void toTRS(Node& n) {
  const glm::mat4& m = n.local;
  n.translation = glm::vec3(m[3]);
  n.scale = glm::vec3(glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])),
                      glm::length(glm::vec3(m[2])));
  n.rotation = glm::quat_cast(glm::mat3(glm::vec3(m[0]) / n.scale.x, glm::vec3(m[1]) / n.scale.y,
                                        glm::vec3(m[2]) / n.scale.z));
  n.hasTRS = true;
}

int nodeWith(const Scene& s, bool light) {
  for (size_t i = 0; i < s.nodes.size(); ++i)
    if (light ? s.nodes[i].light >= 0 : s.nodes[i].camera >= 0) return int(i);
  return -1;
}

// A 2-second looping clip sliding `node` (given TRS first) from `from` at 0 s to `to` at 1 s.
void addSlideClip(Scene& s, int node, const glm::vec3& from, const glm::vec3& to) {
  toTRS(s.nodes[node]);
  AnimationClip clip;
  AnimationSampler sampler;
  sampler.times = {0.0f, 1.0f};
  sampler.components = 3;
  sampler.values = {from.x, from.y, from.z, to.x, to.y, to.z};
  clip.samplers.push_back(sampler);
  clip.channels.push_back({0, node, AnimationPath::Translation});
  clip.duration = 2.0f;
  s.animations.push_back(clip);
}

// A clip on `node`: rotation keys (x, y, z, w) at the given times.
void addRotationClip(Scene& s, int node, const std::vector<float>& times,
                     const std::vector<glm::quat>& keys) {
  AnimationClip clip;
  AnimationSampler sampler;
  sampler.times = times;
  sampler.components = 4;
  for (const glm::quat& q : keys) sampler.values.insert(sampler.values.end(), {q.x, q.y, q.z, q.w});
  clip.samplers.push_back(sampler);
  clip.channels.push_back({0, node, AnimationPath::Rotation});
  clip.duration = times.back();
  s.animations.push_back(clip);
}

// Mean world x of the dark plane pixels (the box's shadow) in a lit image seen from above.
double shadowCentroidX(Renderer& r) {
  const ImageRGBA32F lit = r.readTarget("lit"), depth = r.readTarget("depth");
  const CameraView& cam = r.camera();
  const glm::mat4 inv = glm::inverse(cam.proj * cam.view);
  double sum = 0.0;
  int count = 0;
  for (int y = 0; y < lit.height; ++y)
    for (int x = 0; x < lit.width; ++x) {
      const size_t i = size_t(y) * lit.width + x;
      const glm::vec2 uv((x + 0.5f) / lit.width, (y + 0.5f) / lit.height);
      glm::vec4 w = inv * glm::vec4(uv * 2.0f - 1.0f, depth.pixels[i * 4], 1.0f);
      w /= w.w;
      if (std::abs(w.y) > 1e-3f || std::abs(w.x) > 2.4f || std::abs(w.z) > 2.4f) continue;
      if (lit.pixels[i * 4 + 1] < 0.1f) {  // lit plane: ~1.2; shadow: ambient only (~0.016)
        sum += w.x;
        ++count;
      }
    }
  EXPECT_GT(count, 30);
  return count ? sum / count : 0.0;
}

TEST_F(AnimatedViewTest, RotatingSunMovesTheShadowInOneRenderer) {
  Scene scene = boxScene();
  const int sun = nodeWith(scene, true);
  ASSERT_GE(sun, 0);
  toTRS(scene.nodes[sun]);
  const glm::quat q0 = scene.nodes[sun].rotation;
  const glm::quat half = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));
  addRotationClip(scene, sun, {0.0f, 0.5f, 1.0f}, {q0, half * q0, half * half * q0});
  scene.animate(0.0);

  RenderSettings rs;
  rs.width = 160;
  rs.height = 120;
  rs.view = "lit";
  rs.shadowMapSize = 512;
  Renderer r(ctx(), scene, rs);
  r.setTime(0.0);
  r.renderFrame();
  // The shadow falls on the +x side of the box (light along (1, -2, 0); the part of it under
  // the box is hidden from the camera above, so its visible centroid lies past x = 0.5) ...
  const double before = shadowCentroidX(r);
  EXPECT_GT(before, 0.45);
  EXPECT_LT(before, 0.8);
  const double compileMs = r.lastCompileMs();  // changes only when the graph is rebuilt
  // ... and after half a turn about y (light along (-1, -2, 0)) on the mirrored side.
  const double t = 1.0 - 1e-6;
  r.setTime(t);
  r.renderFrame();
  EXPECT_NEAR(shadowCentroidX(r), -before, 0.02);
  // The same pose through a new renderer gives the same image: setTime re-planned the light
  // records and shadow views exactly as construction does.
  const ImageRGBA32F moved = r.readTarget("lit");
  scene.animate(t);
  Renderer fresh(ctx(), scene, rs);
  fresh.renderFrame();
  const ImageRGBA32F want = fresh.readTarget("lit");
  ASSERT_EQ(moved.pixels.size(), want.pixels.size());
  double worst = 0.0;
  for (size_t i = 0; i < want.pixels.size(); ++i)
    worst = std::max(worst, double(std::abs(moved.pixels[i] - want.pixels[i])));
  EXPECT_LT(worst, 1e-3);
  EXPECT_EQ(r.lastCompileMs(), compileMs) << "moving a light must not rebuild the graph";
}

TEST_F(AnimatedViewTest, MovingCameraFollowsItsNodeAndWritesMotionVectors) {
  Scene scene = boxScene();
  const int cam = nodeWith(scene, false);
  ASSERT_GE(cam, 0);
  addSlideClip(scene, cam, {0, 5, 0}, {0.5f, 5, 0});  // slides 0.5 along +x
  scene.animate(0.0);

  RenderSettings rs;
  rs.width = 80;
  rs.height = 60;
  rs.view = "motion";
  Renderer r(ctx(), scene, rs);
  // Poses set before the first frame have nothing to move from: no motion.
  r.setTime(0.25);
  r.setTime(0.0);
  r.renderFrame();
  const ImageRGBA32F still = r.readTarget("motion");
  for (size_t i = 0; i < still.pixels.size(); i += 4)
    ASSERT_EQ(still.pixels[i], 0.0f) << "motion before any previous frame, pixel " << i / 4;
  const glm::mat4 before = r.camera().proj * r.camera().view;
  r.setTime(0.5);  // the camera is now at x = 0.25
  EXPECT_NEAR(r.camera().position.x, 0.25f, 1e-5f);
  r.renderFrame();
  const ImageRGBA32F motion = r.readTarget("motion");
  const glm::mat4 after = r.camera().proj * r.camera().view;
  // The plane point under the image centre: motion = uv now - uv before (UV units).
  const glm::vec3 p(0.25f, 0.0f, 0.0f);
  auto uv = [](const glm::mat4& m, const glm::vec3& w) {
    const glm::vec4 c = m * glm::vec4(w, 1.0f);
    return glm::vec2(c) / c.w * 0.5f + 0.5f;
  };
  const glm::vec2 want = uv(after, p) - uv(before, p);
  const size_t centre = size_t(30) * 80 + 40;
  EXPECT_GT(std::abs(want.x), 0.01f);
  EXPECT_NEAR(motion.pixels[centre * 4], want.x, 2e-3f);
  EXPECT_NEAR(motion.pixels[centre * 4 + 1], want.y, 2e-3f);
  // Motion is against the last rendered frame: the same pose again moves nothing.
  r.renderFrame();
  const ImageRGBA32F again = r.readTarget("motion");
  for (size_t i = 0; i < again.pixels.size(); i += 4)
    ASSERT_EQ(again.pixels[i], 0.0f) << "camera motion repeated, pixel " << i / 4;
}

// Object motion follows the same rule as the camera's: against the last rendered frame, so a
// pose set twice between frames and a frame rendered twice give consistent vectors.
TEST_F(AnimatedViewTest, ObjectMotionIsAgainstTheLastRenderedFrame) {
  Scene scene = boxScene();
  int box = -1;
  for (size_t i = 0; i < scene.nodes.size(); ++i)
    if (!scene.nodes[i].meshes.empty() && scene.nodes[i].world[3].y > 0.5f) box = int(i);
  ASSERT_GE(box, 0);
  addSlideClip(scene, box, {0, 1, 0}, {1.0f, 1, 0});  // slides 1 along +x
  RenderSettings rs;
  rs.width = 80;
  rs.height = 60;
  rs.view = "motion";
  Renderer r(ctx(), scene, rs);
  r.setTime(0.0);
  r.renderFrame();
  r.setTime(0.5);  // never rendered
  r.setTime(0.25);
  r.renderFrame();
  const ImageRGBA32F moved = r.readTarget("motion");
  float largest = 0.0f;
  for (size_t i = 0; i < moved.pixels.size(); i += 4)
    largest = std::max(largest, std::abs(moved.pixels[i]));
  // 0.25 along x seen from 5 above with a 60-degree view (half-width 5 tan 30 = 2.89 at the
  // plane, less at the box's top 1 higher): about 0.25 / (2 x 2.31) = 0.054 in UV units; the
  // unrendered pose at 0.5 would double it.
  EXPECT_NEAR(largest, 0.25f / (2.0f * 4.0f * std::tan(glm::radians(30.0f))), 0.01f);
  r.renderFrame();
  const ImageRGBA32F still = r.readTarget("motion");
  // (Rounding: the current position comes from gl_FragCoord, the previous one from matrices.)
  for (size_t i = 0; i < still.pixels.size(); i += 4)
    ASSERT_NEAR(still.pixels[i], 0.0f, 1e-5f) << "object motion repeated, pixel " << i / 4;
}

}  // namespace
}  // namespace gi
