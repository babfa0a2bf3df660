// The AO split of the CPU reference (gi-reference --quantity ao-split): every occluded AO ray is
// visible (a depth-layer surface within r), off-screen (first hit outside the view frustum) or
// hidden (inside the frame, behind the visible surface). Constructed cases with known answers:
// a wall inside the frame (all visible), a wall behind the camera (all off-screen, closed form),
// a cube whose side faces only the floor beside it sees (hidden); finite values and consistent
// fractions everywhere, sky included; AO_full is exactly the AO quantity; determinism; the
// command line's extra images. CPU only (no Vulkan).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/image_io.h"
#include "gi/reference/reference.h"
#include "gi/scene_io.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

namespace ref = gi::reference;
constexpr double kPi = 3.14159265358979323846;

// The parallelogram corner + s e1 + t e2 (s, t in [0, 1]), facing cross(e1, e2).
Mesh parallelogram(glm::vec3 corner, glm::vec3 e1, glm::vec3 e2) {
  Mesh m;
  m.name = "parallelogram";
  const glm::vec3 normal = glm::normalize(glm::cross(e1, e2));
  m.vertices = {{corner, normal, {0, 0}},
                {corner + e1, normal, {1, 0}},
                {corner + e1 + e2, normal, {1, 1}},
                {corner + e2, normal, {0, 1}}};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.boundsMin = glm::min(glm::min(corner, corner + e1 + e2), glm::min(corner + e1, corner + e2));
  m.boundsMax = glm::max(glm::max(corner, corner + e1 + e2), glm::max(corner + e1, corner + e2));
  return m;
}

struct SceneBuilder {
  Scene s;
  SceneBuilder() {
    s.sourcePath = "test";
    s.materials.emplace_back();
  }
  void add(Mesh mesh) {
    s.meshes.push_back(std::move(mesh));
    s.nodes[s.addNode("mesh", glm::mat4(1.0f))].meshes = {int(s.meshes.size()) - 1};
  }
  // An axis-aligned box from six parallelograms (surfaces are double-sided).
  void box(glm::vec3 lo, glm::vec3 hi) {
    const glm::vec3 d = hi - lo;
    const glm::vec3 x(d.x, 0, 0), y(0, d.y, 0), z(0, 0, d.z);
    add(parallelogram(lo, z, x));      // bottom
    add(parallelogram(lo + y, z, x));  // top
    add(parallelogram(lo, x, y));      // back
    add(parallelogram(lo + z, x, y));  // front
    add(parallelogram(lo, y, z));      // left
    add(parallelogram(lo + x, y, z));  // right
  }
  void camera(glm::vec3 eye, glm::vec3 target, float yfovDeg = 50.0f) {
    Camera c;
    c.yfov = glm::radians(yfovDeg);
    c.znear = 0.01f;
    c.zfar = 100.0f;
    s.cameras.push_back(c);
    s.activeCameraNode = s.addNode("camera", glm::inverse(glm::lookAt(eye, target, {0, 1, 0})));
    s.nodes[s.activeCameraNode].camera = int(s.cameras.size()) - 1;
  }
  Scene done() {
    s.updateWorldTransforms();
    return s;
  }
};

// A floor y = 0, |x|, |z| <= half.
void addFloor(SceneBuilder& b, float half = 20.0f) {
  b.add(parallelogram({-half, 0, half}, {2 * half, 0, 0}, {0, 0, -2 * half}));
}

ref::Settings splitSettings(uint32_t spp, float radius = 0.5f, uint32_t w = 64, uint32_t h = 48) {
  ref::Settings s;
  s.quantity = ref::Quantity::AOSplit;
  s.radius = radius;
  s.width = w;
  s.height = h;
  s.spp = spp;
  s.threads = 2;
  return s;
}

// One pixel of an ao-split result.
struct SplitPixel {
  bool geometry = false;
  glm::vec3 position{0.0f};
  double full = 0, fullSe = 0;          // AO_full and its standard error
  double visibleAo = 0, visibleSe = 0;  // AO_visible
  double offscreen = 0, offscreenSe = 0, hidden = 0, hiddenSe = 0;
  double visible() const { return 1.0 - visibleAo; }  // visible-occluded fraction
};
SplitPixel at(const ref::Result& r, size_t i) {
  SplitPixel p;
  p.geometry = r.depth.pixels[i * 4 + 3] > 0.5f;
  p.position = glm::vec3(r.position.pixels[i * 4], r.position.pixels[i * 4 + 1],
                         r.position.pixels[i * 4 + 2]);
  p.full = r.value.pixels[i * 4];
  p.fullSe = r.stdError.pixels[i * 4];
  p.visibleAo = r.split.pixels[i * 4];
  p.offscreen = r.split.pixels[i * 4 + 1];
  p.hidden = r.split.pixels[i * 4 + 2];
  p.visibleSe = r.splitStdError.pixels[i * 4];
  p.offscreenSe = r.splitStdError.pixels[i * 4 + 1];
  p.hiddenSe = r.splitStdError.pixels[i * 4 + 2];
  return p;
}
size_t pixelCount(const ref::Result& r) {
  return size_t(r.value.width) * size_t(r.value.height);
}

bool allFinite(const ImageRGBA32F& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}

// The fraction of a point's cosine-weighted hemisphere that an infinite perpendicular wall at
// distance d hides within r (test_scene_reference.cpp derives it): the circular segment.
double wallFraction(double d, double r) {
  const double a = d / r;
  if (a >= 1.0) return 0.0;
  return (std::acos(a) - a * std::sqrt(1.0 - a * a)) / kPi;
}

// Checks what every split must satisfy: finite images of the right size, sky pixels fully open
// with zero fractions and errors, fractions in [0, 1] summing to 1 - AO_full.
void checkConsistent(const ref::Result& r, const char* what) {
  const size_t n = pixelCount(r);
  ASSERT_EQ(r.split.pixels.size(), n * 4) << what;
  ASSERT_EQ(r.splitStdError.pixels.size(), n * 4) << what;
  EXPECT_TRUE(allFinite(r.value) && allFinite(r.stdError) && allFinite(r.split) &&
              allFinite(r.splitStdError))
      << what;
  EXPECT_TRUE(std::isfinite(r.meanStdError)) << what;
  for (size_t i = 0; i < n; ++i) {
    const SplitPixel p = at(r, i);
    if (!p.geometry) {
      EXPECT_EQ(p.full, 1.0) << what << " sky pixel " << i;
      EXPECT_EQ(p.visibleAo, 1.0) << what;
      EXPECT_EQ(p.offscreen, 0.0) << what;
      EXPECT_EQ(p.hidden, 0.0) << what;
      EXPECT_EQ(r.split.pixels[i * 4 + 3], 0.0f) << what;
      EXPECT_EQ(p.fullSe + p.visibleSe + p.offscreenSe + p.hiddenSe, 0.0) << what;
      continue;
    }
    EXPECT_EQ(r.split.pixels[i * 4 + 3], 1.0f) << what;
    for (double f : {p.full, p.visibleAo, p.offscreen, p.hidden}) {
      EXPECT_GE(f, 0.0) << what << " pixel " << i;
      EXPECT_LE(f, 1.0) << what << " pixel " << i;
    }
    EXPECT_LE(p.full, p.visibleAo + 1e-6) << what << " pixel " << i;
    EXPECT_NEAR(1.0 - p.full, p.visible() + p.offscreen + p.hidden, 1e-5) << what << " pixel " << i;
  }
}

// --- (i) an occluder fully inside the frame ---------------------------------------------------

TEST(ReferenceAoSplit, WallInsideTheFrameIsAllVisible) {
  // A wall 1.2 wide, 0.5 high standing on a floor, facing the camera, all of it in the frame:
  // the floor's occlusion comes from the wall only (front or, behind it, back side: the same
  // points the depth buffer holds), so nothing is off-screen or hidden.
  SceneBuilder b;
  addFloor(b);
  b.add(parallelogram({-0.6f, 0, 0}, {1.2f, 0, 0}, {0, 0.5f, 0}));
  b.camera({0.3f, 1.2f, 2.2f}, {0, 0.1f, 0});
  const ref::Result r = ref::render(b.done(), splitSettings(256));
  checkConsistent(r, "wall in frame");
  int occluded = 0;
  double hidden = 0.0;
  size_t geometry = 0;
  for (size_t i = 0; i < pixelCount(r); ++i) {
    const SplitPixel p = at(r, i);
    if (!p.geometry) continue;
    ++geometry;
    EXPECT_EQ(p.offscreen, 0.0) << "pixel " << i;
    EXPECT_NEAR(p.visibleAo, p.full, 5.0 * p.visibleSe + 1e-6)
        << "pixel " << i << " at " << p.position.x << "," << p.position.y << "," << p.position.z;
    hidden += p.hidden;
    occluded += p.full < 0.9;
  }
  EXPECT_GT(occluded, 100) << "the wall must occlude part of the floor";
  // Sub-pixel misses at the wall's silhouette are the only possible hidden hits.
  EXPECT_LT(hidden / double(geometry), 1e-4);
}

// --- (ii) an occluder outside the frame -------------------------------------------------------

TEST(ReferenceAoSplit, WallBehindTheCameraIsOffscreen) {
  // Floor y = 0 (x >= 0) meeting the wall x = 0. The camera at (0.35, 1, 0) looks 75 degrees
  // down, towards +x: the frame's lower edge is 10 degrees past the vertical and shows the floor
  // from x = 0.17 on, while the wall (at least 19 degrees past the vertical) is outside the
  // frustum. The floor's occlusion is the wall's circular segment F(x / r), all of it off-screen:
  // AO_visible = 1 exactly, AO_full = 1 - F.
  SceneBuilder b;
  b.add(parallelogram({0, 0, 2}, {4, 0, 0}, {0, 0, -4}));
  b.add(parallelogram({0, 0, -2}, {0, 4, 0}, {0, 0, 4}));
  const glm::vec3 eye(0.35f, 1.0f, 0.0f);
  const float pitch = glm::radians(75.0f);
  b.camera(eye, eye + glm::vec3(std::cos(pitch), -std::sin(pitch), 0.0f));
  const float radius = 0.5f;
  const ref::Result r = ref::render(b.done(), splitSettings(256, radius));
  checkConsistent(r, "wall behind the camera");
  int nearWall = 0, checked = 0;
  double residual = 0.0, variance = 0.0, fullNearWall = 0.0;
  for (size_t i = 0; i < pixelCount(r); ++i) {
    const SplitPixel p = at(r, i);
    ASSERT_TRUE(p.geometry) << "the floor fills the frame";
    ASSERT_NEAR(p.position.y, 0.0f, 1e-5f) << "only the floor is in the frame";
    EXPECT_EQ(p.visibleAo, 1.0) << "pixel " << i;
    EXPECT_EQ(p.hidden, 0.0) << "pixel " << i;
    const double d = p.position.x;
    if (std::abs(p.position.z) > 1.5f) continue;  // the finite wall looks infinite
    const double f = wallFraction(d, radius);
    // Samples in [0, 1]: a pixel whose samples are all equal reports se = 0.
    const double bound = std::max(p.offscreenSe, std::sqrt(f * (1 - f) / r.spp));
    EXPECT_NEAR(p.offscreen, f, 5.0 * bound + 0.005) << "x = " << d;
    EXPECT_NEAR(p.full, 1.0 - p.offscreen, 1e-6);
    residual += p.offscreen - f;
    variance += p.offscreenSe * p.offscreenSe;
    ++checked;
    if (d < 0.25) {
      ++nearWall;
      fullNearWall += p.full;
    }
  }
  ASSERT_GT(checked, 1000);
  EXPECT_LE(std::abs(residual / checked), 4.0 * std::sqrt(variance) / checked + 0.001);
  ASSERT_GT(nearWall, 50) << "the frame must show the floor next to the wall";
  EXPECT_LT(fullNearWall / nearWall, 0.9) << "AO_full < 1 near the wall";
}

// --- (iii) an occluder behind the visible layer -----------------------------------------------

TEST(ReferenceAoSplit, CubeSideFacesAreHiddenFromTheCamera) {
  // A unit cube on the floor, the camera straight in front of it (x = 0) and above: its side
  // faces x = +-0.5 are behind its front and top faces from the camera, but they occlude the
  // floor beside the cube. The floor in front of the cube sees the visible front face.
  SceneBuilder b;
  addFloor(b);
  b.box({-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f});
  b.camera({0, 1.8f, 3.0f}, {0, 0.3f, 0});
  const float radius = 0.5f;
  const ref::Result r = ref::render(b.done(), splitSettings(256, radius, 96, 72));
  checkConsistent(r, "cube");
  double besideHidden = 0.0, besideOccluded = 0.0, frontHidden = 0.0, frontVisible = 0.0;
  int beside = 0, front = 0;
  for (size_t i = 0; i < pixelCount(r); ++i) {
    const SplitPixel p = at(r, i);
    if (!p.geometry) continue;
    EXPECT_EQ(p.offscreen, 0.0) << "the cube is inside the frame";
    if (std::abs(p.position.y) > 1e-5f) continue;  // floor points only
    const float ax = std::abs(p.position.x), z = p.position.z;
    if (ax > 0.55f && ax < 0.8f && std::abs(z) < 0.3f) {  // beside the cube, facing a side
      besideHidden += p.hidden;
      besideOccluded += 1.0 - p.full;
      ++beside;
    }
    if (ax < 0.3f && z > 0.55f && z < 0.8f) {  // in front of the cube, facing its front
      frontHidden += p.hidden;
      frontVisible += p.visible();
      ++front;
    }
  }
  ASSERT_GT(beside, 20);
  ASSERT_GT(front, 20);
  // Beside: the side face (distance d from the point) hides about F(d / r) of the hemisphere;
  // rays that go through it and leave by the visible front or top face within r count visible.
  EXPECT_GT(besideOccluded / beside, 0.05);
  EXPECT_GT(besideHidden / beside, 0.03) << "hidden share must be measured";
  EXPECT_GT(besideHidden / besideOccluded, 0.5) << "most of it is the hidden side faces";
  EXPECT_GT(frontVisible / front, 0.05);
  EXPECT_LT(frontHidden / front, 0.01 * frontVisible / front);
  // The diagnostics: hidden rays whose first hit lies in front of the layer are rare; rays that
  // enter a side face near the front edge leave by the visible front face within r and count
  // visible (a depth-buffer method sees that face).
  EXPECT_LT(double(r.splitHiddenInFront), 0.01 * double(r.splitOccluded));
  EXPECT_GT(r.splitVisibleBehind, 0u);
  EXPECT_LT(r.splitVisibleBehind, r.splitOccluded);
}

// --- (iv) consistency, sky, determinism -------------------------------------------------------

TEST(ReferenceAoSplit, FiniteAndConsistentEverywhereIncludingSky) {
  // Scenes with sky pixels, an empty scene and the default room.
  {
    SceneBuilder b;
    addFloor(b, 2.0f);
    b.box({-0.3f, 0, -0.3f}, {0.3f, 0.6f, 0.3f});
    b.camera({1.5f, 0.8f, 1.5f}, {0, 0.4f, 0});  // looks above the floor's far edge
    const ref::Result r = ref::render(b.done(), splitSettings(32, 0.5f, 48, 36));
    ASSERT_GT(r.geometryPixels, 100u);
    ASSERT_LT(r.geometryPixels, 48u * 36u) << "the view must include sky";
    checkConsistent(r, "box with sky");
  }
  {
    // Camera inside a small closed box (every pixel geometry, occluders behind the camera and
    // nearer than znear), plus zero vertex normals and a zero-area triangle.
    SceneBuilder b;
    b.box({-0.2f, -0.2f, -0.2f}, {0.2f, 0.2f, 0.2f});
    Mesh m = parallelogram({-0.1f, -0.15f, 0.1f}, {0.2f, 0, 0}, {0, 0, -0.2f});
    for (Vertex& v : m.vertices) v.normal = glm::vec3(0.0f);
    m.indices.insert(m.indices.end(), {0, 0, 1});
    b.add(m);
    b.camera({0.05f, 0.0f, 0.05f}, {0, -0.1f, -1.0f}, 90.0f);
    const ref::Result r = ref::render(b.done(), splitSettings(16, 0.5f, 24, 18));
    EXPECT_EQ(r.geometryPixels, 24u * 18u);
    checkConsistent(r, "camera inside a box");
    EXPECT_GT(ref::summarizeAoSplit(r).offscreen, 0.0) << "walls behind the camera";
  }
  {
    Scene empty;
    empty.updateWorldTransforms();
    const ref::Result r = ref::render(empty, splitSettings(4, 0.5f, 24, 18));
    EXPECT_EQ(r.geometryPixels, 0u);
    checkConsistent(r, "empty scene");
    const ref::AoSplitSummary s = ref::summarizeAoSplit(r);
    EXPECT_EQ(s.pixels, 0u);
    EXPECT_EQ(s.limitNrmse, 0.0);
  }
  {
    const ref::Result r = ref::render(loadScene("default"), splitSettings(32, 0.5f, 80, 60));
    checkConsistent(r, "default scene");
    const ref::AoSplitSummary s = ref::summarizeAoSplit(r);
    EXPECT_EQ(s.pixels, r.geometryPixels);
    EXPECT_NEAR(1.0 - s.aoFull, s.visible + s.offscreen + s.hidden, 1e-5);
    EXPECT_GT(s.hidden, 0.0) << "the room's blocks hide occluders";
    EXPECT_TRUE(std::isfinite(s.limitNrmse));
    EXPECT_GT(s.limitNrmse, 0.0);
  }
}

TEST(ReferenceAoSplit, FullIsExactlyTheAoQuantityAndDeterministic) {
  // The split traces the AO estimator's own rays: its value image and standard error are the AO
  // quantity's, bit for bit, and any thread count gives the same images.
  const Scene scene = loadScene("default");
  ref::Settings s = splitSettings(16, 0.5f, 40, 30);
  s.seed = 5;
  s.threads = 1;
  const ref::Result a = ref::render(scene, s);
  s.threads = 3;
  const ref::Result b = ref::render(scene, s);
  EXPECT_EQ(a.value.pixels, b.value.pixels);
  EXPECT_EQ(a.split.pixels, b.split.pixels);
  EXPECT_EQ(a.splitStdError.pixels, b.splitStdError.pixels);
  EXPECT_EQ(a.splitOccluded, b.splitOccluded);
  EXPECT_EQ(a.splitHiddenInFront, b.splitHiddenInFront);
  ref::Settings ao = s;
  ao.quantity = ref::Quantity::AO;
  const ref::Result c = ref::render(scene, ao);
  EXPECT_EQ(a.value.pixels, c.value.pixels);
  EXPECT_EQ(a.stdError.pixels, c.stdError.pixels);
  EXPECT_EQ(a.meanStdError, c.meanStdError);
  EXPECT_EQ(ref::parseQuantity("ao-split"), ref::Quantity::AOSplit);
  EXPECT_STREQ(ref::quantityName(ref::Quantity::AOSplit), "ao-split");
}

// --- command line -----------------------------------------------------------------------------

TEST(ReferenceAoSplitCli, WritesTheSplitImagesAndSummary) {
  const std::string dir = test::makeTempDir("reference-ao-split");
  auto r = test::runCommand(test::binPath("gi-reference") +
                            " --quiet --scene default --quantity ao-split --spp 8 --width 40 "
                            "--height 30 --seed 3 --threads 2 --out '" +
                            dir + "/ao.pfm' --png '" + dir + "/ao.png'");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("screen-space limit NRMSE"), std::string::npos) << r.output;
  ref::Settings s = splitSettings(8, 0.5f, 40, 30);
  s.seed = 3;
  const ref::Result lib = ref::render(loadScene("default"), s);
  const char* names[3] = {"visible", "offscreen", "hidden"};
  for (int c = 0; c < 3; ++c) {
    const ImageRGBA32F img = readPfm(dir + "/ao." + names[c] + ".pfm");
    ASSERT_EQ(img.width, 40);
    for (size_t i = 0; i < 40 * 30; ++i)
      ASSERT_EQ(img.pixels[i * 4], lib.split.pixels[i * 4 + size_t(c)]) << names[c];
    EXPECT_EQ(readPng(dir + "/ao." + names[c] + ".png").width, 40) << names[c];
  }
  const ImageRGBA32F full = readPfm(dir + "/ao.pfm");
  for (size_t i = 0; i < 40 * 30; ++i) ASSERT_EQ(full.pixels[i * 4], lib.value.pixels[i * 4]);
  EXPECT_TRUE(allFinite(readPfm(dir + "/ao.split.stderr.pfm")));
  EXPECT_TRUE(allFinite(readPfm(dir + "/ao.stderr.pfm")));
}

}  // namespace
}  // namespace gi
