// Shadow maps: a box above a plane under directional, spot and point lights darkens the
// analytically expected footprint and nothing else; no acne on the lit plane at the default
// bias; a box on a plane under grazing light keeps its lit faces and the open floor as bright
// as without shadows for every PCF radius (no self-shadowing moire); shadow passes exist only
// for shadow-casting lights whose result lighting reads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "process.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

using test::VulkanTest;

const glm::vec3 kBoxMin(-0.25f, 0.75f, -0.25f), kBoxMax(0.25f, 1.25f, 0.25f);

std::string lightJson(const std::string& type) {
  if (type == "directional")
    return R"({"type": "directional", "direction": [1, -2, 0], "intensity": 3})";
  if (type == "spot")
    return R"({"type": "spot", "position": [-1.2, 3, 0.2], "direction": [0.45, -1, -0.07],
               "outer_cone_deg": 60, "inner_cone_deg": 50, "intensity": 30})";
  return R"({"type": "point", "position": [-1.0, 2.5, 0.3], "intensity": 20})";
}

// Plane y = 0 (5 x 5), a 0.5 box floating at y = 1, camera straight above, dim constant sky,
// and the given JSON light objects (comma-separated).
Scene boxSceneWithLights(const std::string& lights) {
  const std::string dir = test::makeTempDir("shadow-scene");
  const std::string path = dir + "/scene.json";
  std::ofstream(path) << R"({
    "models": [
      {"primitive": "plane", "size": 5, "material": {"base_color": [0.8, 0.8, 0.8]}},
      {"primitive": "box", "size": 0.5, "translation": [0, 1, 0]}],
    "camera": {"position": [0, 5, 0], "target": [0, 0, 0], "up": [0, 0, -1], "yfov_deg": 60},
    "lights": [)" + lights +
                             R"(],
    "environment": {"type": "constant", "color": [1, 1, 1], "intensity": 0.02}})";
  return loadScene(path);
}

Scene boxScene(const std::string& light) {
  return boxSceneWithLights(lightJson(light));
}

// Whether the ray o + t d, 1e-4 < t < tMax, meets the box [lo, hi] (slab test).
bool rayHitsBox(const glm::vec3& o, const glm::vec3& d, float tMax, const glm::vec3& lo = kBoxMin,
                const glm::vec3& hi = kBoxMax) {
  float t0 = 1e-4f, t1 = tMax;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12f) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    float ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

struct Frame {
  ImageRGBA32F lit, depth;
  CameraView camera;
};

Frame render(vk::Context& ctx, const Scene& scene, uint32_t shadowSize = 512,
             uint32_t pcfRadius = 1) {
  RenderSettings rs;
  rs.width = 160;
  rs.height = 120;
  rs.view = "lit";
  rs.shadowMapSize = shadowSize;
  rs.pcfRadius = pcfRadius;
  Renderer r(ctx, scene, rs);
  r.renderFrame();
  return {r.readTarget("lit"), r.readTarget("depth"), r.camera()};
}

glm::vec3 worldPosition(const Frame& f, int x, int y) {
  const float d = f.depth.pixels[(size_t(y) * f.depth.width + x) * 4];
  const glm::vec2 uv((x + 0.5f) / f.depth.width, (y + 0.5f) / f.depth.height);
  glm::vec4 v = glm::inverse(f.camera.proj) * glm::vec4(uv * 2.0f - 1.0f, d, 1.0f);
  v /= v.w;
  return glm::vec3(glm::inverse(f.camera.view) * v);
}

class ShadowTest : public VulkanTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(ShadowTest, BoxShadowFallsOnTheExpectedPixelsOnly) {
  const std::string type = GetParam();
  Scene scene = boxScene(type);
  const Frame shadowed = render(ctx(), scene);
  for (Light& l : scene.lights) l.castsShadows = false;
  const Frame open = render(ctx(), scene);

  const Node* lightNode = nullptr;
  for (const Node& n : scene.nodes)
    if (n.light >= 0) lightNode = &n;
  ASSERT_NE(lightNode, nullptr);
  const glm::vec3 lightPos(lightNode->world[3]);
  const glm::vec3 lightDir = glm::normalize(glm::vec3(lightNode->world * glm::vec4(0, 0, -1, 0)));

  int inside = 0, outside = 0, darkInside = 0;
  std::vector<float> ratios;
  for (int y = 0; y < shadowed.lit.height; ++y)
    for (int x = 0; x < shadowed.lit.width; ++x) {
      const glm::vec3 p = worldPosition(shadowed, x, y);
      if (std::abs(p.y) > 1e-3f || std::abs(p.x) > 2.4f || std::abs(p.z) > 2.4f) continue;
      // Classify with a margin around the footprint's edge (PCF and texel quantisation).
      auto occluded = [&](const glm::vec3& q) {
        if (type == "directional") return rayHitsBox(q, -lightDir, 100.0f);
        const glm::vec3 toLight = lightPos - q;
        return rayHitsBox(q, toLight / glm::length(toLight), glm::length(toLight));
      };
      int hits = 0;
      const float m = 0.06f;
      for (glm::vec2 o :
           {glm::vec2(0), glm::vec2(m, 0), glm::vec2(-m, 0), glm::vec2(0, m), glm::vec2(0, -m),
            glm::vec2(m, m), glm::vec2(-m, -m), glm::vec2(m, -m), glm::vec2(-m, m)})
        hits += occluded(p + glm::vec3(o.x, 0, o.y)) ? 1 : 0;
      const size_t i = (size_t(y) * shadowed.lit.width + x) * 4;
      const float s = shadowed.lit.pixels[i + 1], u = open.lit.pixels[i + 1];
      if (hits == 9) {
        ++inside;
        // Only the ambient term remains (0.02 * albedo): far below the direct light.
        if (s < 0.2f * u) ++darkInside;
      } else if (hits == 0 && u > 0.05f) {
        ++outside;
        ratios.push_back(s / u);
      }
    }
  EXPECT_GT(inside, 30) << "footprint not on screen";
  EXPECT_GT(outside, 1000);
  EXPECT_EQ(darkInside, inside) << type << ": pixels inside the footprint left lit";
  // No acne: the lit plane equals the unshadowed render within a tight tolerance.
  size_t bad = 0;
  for (float r : ratios)
    if (std::abs(r - 1.0f) > 0.005f) ++bad;
  EXPECT_EQ(bad, 0u) << type << ": " << bad << " of " << ratios.size()
                     << " lit plane pixels differ from the unshadowed render";
}

INSTANTIATE_TEST_SUITE_P(LightTypes, ShadowTest, ::testing::Values("directional", "spot", "point"));

// A unit box standing on a plane, seen from above one corner, under one light at a grazing
// angle: "steep" comes from high above, grazing the box's sides (as the Cornell box's lamp grazes
// its blocks' fronts, whose tops are the nearer faces beside them in the map), "point" is a point
// light just above the box doing the same through a cube map (the Cornell box's case), "low"
// skims the floor (ndl 0.12) and grazes the box's +z face.
struct GrazingCase {
  std::string name, light;
  int pcfRadius;
};
void PrintTo(const GrazingCase& c, std::ostream* os) {
  *os << c.name;
}

class GrazingShadowTest : public VulkanTest, public ::testing::WithParamInterface<GrazingCase> {};

TEST_P(GrazingShadowTest, LitFacesAndTheOpenFloorAreAsBrightAsWithoutShadows) {
  const GrazingCase& c = GetParam();
  const std::string dir = test::makeTempDir("grazing-shadow");
  std::ofstream(dir + "/scene.json") << R"({
    "models": [
      {"primitive": "plane", "size": 5, "material": {"base_color": [0.8, 0.8, 0.8]}},
      {"primitive": "box", "size": 1, "translation": [0, 0.5, 0],
       "material": {"base_color": [0.8, 0.8, 0.8]}}],
    "camera": {"position": [2.6, 2.3, 2.9], "target": [0, 0.35, 0], "yfov_deg": 55},
    "lights": [)" + c.light +
                                            R"(],
    "environment": {"type": "constant", "color": [1, 1, 1], "intensity": 0.02}})";
  Scene scene = loadScene(dir + "/scene.json");
  const Frame shadowed = render(ctx(), scene, 512, uint32_t(c.pcfRadius));
  for (Light& l : scene.lights) l.castsShadows = false;
  const Frame open = render(ctx(), scene, 512, uint32_t(c.pcfRadius));
  const Node* lightNode = nullptr;
  for (const Node& n : scene.nodes)
    if (n.light >= 0) lightNode = &n;
  ASSERT_NE(lightNode, nullptr);
  const bool point = scene.lights[0].type == LightType::Point;
  const glm::vec3 lightPos(lightNode->world[3]);
  const glm::vec3 lightDir = -glm::normalize(glm::vec3(lightNode->world * glm::vec4(0, 0, -1, 0)));
  auto toLightAt = [&](const glm::vec3& q) {
    return point ? glm::normalize(lightPos - q) : lightDir;
  };

  // Lit pixels: faces of the (convex) box turned toward the light, which nothing shadows, and
  // floor pixels whose whole neighbourhood (0.06 around) sees the light past the box.
  const glm::vec3 lo(-0.5f, 0.0f, -0.5f), hi(0.5f, 1.0f, 0.5f);
  auto hitsBox = [&](const glm::vec3& o) {
    return rayHitsBox(o, toLightAt(o), point ? glm::length(lightPos - o) : 100.0f, lo, hi);
  };
  const float edge = 0.03f, m = 0.06f;
  size_t faces = 0, floor = 0, darkFaces = 0, darkFloor = 0;
  float worst = 1.0f;
  for (int y = 0; y < shadowed.lit.height; ++y)
    for (int x = 0; x < shadowed.lit.width; ++x) {
      const glm::vec3 p = worldPosition(shadowed, x, y);
      glm::vec3 n(0.0f);
      bool onBox = false;
      for (int a = 0; a < 3 && !onBox; ++a)
        for (float side : {lo[a], hi[a]}) {
          const int b = (a + 1) % 3, d = (a + 2) % 3;
          if (std::abs(p[a] - side) < 2e-3f && p[b] > lo[b] + edge && p[b] < hi[b] - edge &&
              p[d] > lo[d] + edge && p[d] < hi[d] - edge && !(a == 1 && side == 0.0f)) {
            n[a] = side == lo[a] ? -1.0f : 1.0f;
            onBox = true;
            break;
          }
        }
      bool lit = false;
      if (onBox) {
        lit = glm::dot(n, toLightAt(p)) > 0.05f;
      } else if (std::abs(p.y) < 1e-3f && std::abs(p.x) < 2.4f && std::abs(p.z) < 2.4f) {
        lit = true;
        for (glm::vec2 o :
             {glm::vec2(0), glm::vec2(m, 0), glm::vec2(-m, 0), glm::vec2(0, m), glm::vec2(0, -m),
              glm::vec2(m, m), glm::vec2(-m, -m), glm::vec2(m, -m), glm::vec2(-m, m)}) {
          const glm::vec3 q = p + glm::vec3(o.x, 0, o.y);
          const bool insideBase = q.x > lo.x && q.x < hi.x && q.z > lo.z && q.z < hi.z;
          lit = lit && !insideBase && !hitsBox(q);
        }
      }
      if (!lit) continue;
      const size_t i = (size_t(y) * shadowed.lit.width + x) * 4;
      const float ratio = shadowed.lit.pixels[i + 1] / std::max(open.lit.pixels[i + 1], 1e-6f);
      worst = std::min(worst, ratio);
      // The ambient term is 0.02 x albedo; a grazing face's direct light is a few times that:
      // one shadowed tap of 9..49 takes 1-10% off. 1% is the stated tolerance.
      const bool dark = ratio < 0.99f;
      (onBox ? faces : floor) += 1;
      (onBox ? darkFaces : darkFloor) += dark ? 1 : 0;
    }
  EXPECT_GT(faces, 300u) << c.name << ": the lit faces are not on screen";
  EXPECT_GT(floor, 2000u) << c.name;
  EXPECT_EQ(darkFaces, 0u) << c.name << ": " << darkFaces << " of " << faces
                           << " lit box-face pixels darker than without shadows (worst ratio "
                           << worst << ")";
  EXPECT_EQ(darkFloor, 0u) << c.name << ": " << darkFloor << " of " << floor
                           << " open-floor pixels darker than without shadows (worst ratio "
                           << worst << ")";
}

INSTANTIATE_TEST_SUITE_P(
    PcfRadii, GrazingShadowTest,
    ::testing::Values(
        GrazingCase{"steep_r1", R"({"type": "directional", "direction": [-0.12, -1, -0.08]})", 1},
        GrazingCase{"steep_r3", R"({"type": "directional", "direction": [-0.12, -1, -0.08]})", 3},
        GrazingCase{"point_r1",
                    R"({"type": "point", "position": [0.7, 2.4, 0.62], "intensity": 20})", 1},
        GrazingCase{"point_r2",
                    R"({"type": "point", "position": [0.7, 2.4, 0.62], "intensity": 20})", 2},
        GrazingCase{"low_r1", R"({"type": "directional", "direction": [-1, -0.12, -0.3]})", 1},
        GrazingCase{"low_r2", R"({"type": "directional", "direction": [-1, -0.12, -0.3]})", 2}),
    [](const auto& info) { return info.param.name; });

using Passes = std::vector<std::string>;

class ShadowGraphTest : public VulkanTest {};

TEST_F(ShadowGraphTest, ShadowPassOnlyForShadowCastingLightsThatLightingReads) {
  Scene scene = boxScene("spot");
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  rs.shadowMapSize = 256;
  {
    Renderer r(ctx(), scene, rs);
    r.renderFrame();
    EXPECT_EQ(r.passNames(), (Passes{"gbuffer", "shadow_0", "lighting", "tonemap"}));
    const ImageRGBA32F map = r.readTarget("shadow_maps");  // layer 0
    EXPECT_EQ(map.width, 256);
    float maxDepth = 0.0f;
    for (size_t i = 0; i < map.pixels.size(); i += 4) maxDepth = std::max(maxDepth, map.pixels[i]);
    EXPECT_GT(maxDepth, 0.0f) << "nothing rendered into the shadow map";
  }
  {
    RenderSettings normal = rs;
    normal.view = "normal";  // lighting culled: its shadow pass too
    Renderer r(ctx(), scene, normal);
    r.renderFrame();
    EXPECT_EQ(r.passNames(), (Passes{"gbuffer", "gbuffer_normal"}));
    const Passes culled = r.culledPassNames();
    EXPECT_NE(std::find(culled.begin(), culled.end(), "shadow_0"), culled.end());
  }
  scene.lights[0].castsShadows = false;
  {
    Renderer r(ctx(), scene, rs);
    r.renderFrame();
    EXPECT_EQ(r.passNames(), (Passes{"gbuffer", "lighting", "tonemap"}));
    // The G-buffer's unpacking passes (nothing reads a channel) and the floor.
    EXPECT_EQ(r.culledPassNames(), (Passes{"gbuffer_normal", "gbuffer_albedo", "gbuffer_material",
                                           "gbuffer_emission", "floor"}));
  }
}

TEST_F(ShadowGraphTest, PointLightRendersSixFacesIntoOneAtlas) {
  Scene scene = boxScene("point");
  RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  rs.shadowMapSize = 128;
  Renderer r(ctx(), scene, rs);
  r.renderFrame();
  const ImageRGBA32F map = r.readTarget("shadow_maps");
  EXPECT_EQ(map.width, 3 * 128);
  EXPECT_EQ(map.height, 2 * 128);
}

// No limit on shadowed lights (the maps are layers of one array): six spot lights all cast, and
// the sixth light's shadow is really there (turning it off changes the image).
TEST_F(ShadowGraphTest, MoreThanFourShadowedLights) {
  std::string lights;
  for (int i = 0; i < 6; ++i) {
    const float a = float(i) * 1.047f;
    lights += std::string(i ? "," : "") + R"({"type": "spot", "position": [)" +
              std::to_string(1.5f * std::cos(a)) + ", 3, " + std::to_string(1.5f * std::sin(a)) +
              R"(], "direction": [)" + std::to_string(-0.4f * std::cos(a)) + ", -1, " +
              std::to_string(-0.4f * std::sin(a)) +
              R"(], "outer_cone_deg": 50, "inner_cone_deg": 40, "intensity": 8})";
  }
  Scene scene = boxSceneWithLights(lights);
  RenderSettings rs;
  rs.width = 80;
  rs.height = 60;
  rs.shadowMapSize = 128;
  rs.view = "lit";
  Renderer all(ctx(), scene, rs);
  all.renderFrame();
  EXPECT_EQ(all.passNames(), (Passes{"gbuffer", "shadow_0", "shadow_1", "shadow_2", "shadow_3",
                                     "shadow_4", "shadow_5", "lighting"}));
  const ImageRGBA32F withSixth = all.readTarget("lit");
  scene.lights[5].castsShadows = false;
  Renderer five(ctx(), scene, rs);
  five.renderFrame();
  const ImageRGBA32F withoutSixth = five.readTarget("lit");
  int brighter = 0;
  for (size_t i = 0; i < withSixth.pixels.size(); i += 4)
    brighter += withoutSixth.pixels[i] > withSixth.pixels[i] + 1e-3f;
  EXPECT_GT(brighter, 20) << "the sixth light's shadow is missing";
  for (size_t i = 0; i < withSixth.pixels.size(); i += 4)
    EXPECT_LE(withSixth.pixels[i], withoutSixth.pixels[i] + 1e-6f);
}

}  // namespace
}  // namespace gi
