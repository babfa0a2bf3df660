#include "hard_cases.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/effect.h"
#include "gi/effect_config.h"
#include "gi/engine_settings.h"
#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/gbuffer.h"
#include "gi/renderer.h"

namespace gi::bench {
namespace {

// ---- Scene building -------------------------------------------------------------------------

// A square of half size `half` in the local xy plane, facing +z.
Mesh quadMesh(float half, glm::vec3 normal = glm::vec3(0, 0, 1)) {
  Mesh m;
  m.name = "quad";
  for (auto [x, y] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}})
    m.vertices.push_back({glm::vec3(x * half, y * half, 0), normal, glm::vec2(x, y)});
  m.indices = {0, 1, 2, 0, 2, 3};
  m.boundsMin = glm::vec3(-half, -half, 0);
  m.boundsMax = glm::vec3(half, half, 0);
  m.triangleAreas = {2 * half * half, 2 * half * half};
  return m;
}

glm::mat4 translate(glm::vec3 t) {
  return glm::translate(glm::mat4(1.0f), t);
}
glm::mat4 rotate(float degrees, glm::vec3 axis) {
  return glm::rotate(glm::mat4(1.0f), glm::radians(degrees), axis);
}
// The floor y = 0 facing +y; a wall x = 0 facing +x.
const glm::mat4 kFloor = rotate(-90.0f, glm::vec3(1, 0, 0));
const glm::mat4 kWall = rotate(90.0f, glm::vec3(0, 1, 0));

struct Builder {
  Scene s;
  explicit Builder(glm::vec3 albedo = glm::vec3(0.8f)) {
    s.sourcePath = "hard-case";
    Material m;
    m.baseColor = glm::vec4(albedo, 1.0f);
    s.materials.push_back(m);
  }
  int mesh(Mesh m, const glm::mat4& world) {
    s.meshes.push_back(std::move(m));
    const int n = s.addNode(s.meshes.back().name, world);
    s.nodes[n].meshes = {int(s.meshes.size()) - 1};
    return n;
  }
  void quad(const glm::mat4& world, float half) { mesh(quadMesh(half), world); }
  void sun(glm::vec3 towardLight = glm::vec3(0.4f, 1.0f, 0.3f)) {
    Light l;
    l.type = LightType::Directional;
    l.intensity = 3.0f;
    s.lights.push_back(l);
    const int n = s.addNode(
        "sun", glm::inverse(glm::lookAt(
                   glm::vec3(0), -towardLight,
                   glm::abs(towardLight.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0))));
    s.nodes[n].light = int(s.lights.size()) - 1;
  }
  Scene camera(glm::vec3 eye, glm::vec3 target, float znear = 0.05f, float zfar = 100.0f,
               float yfovDegrees = 60.0f) {
    Camera c;
    c.yfov = glm::radians(yfovDegrees);
    c.znear = znear;
    c.zfar = zfar;
    s.cameras.push_back(c);
    const glm::vec3 up =
        std::abs(glm::normalize(target - eye).y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
    const int n = s.addNode("camera", glm::inverse(glm::lookAt(eye, target, up)));
    s.nodes[n].camera = 0;
    s.activeCameraNode = n;
    s.updateWorldTransforms();
    return std::move(s);
  }
};

// Floor and wall meeting at x = 0 (a 90-degree crease), seen from (2.5, 1.6, 0), lit by a sun;
// every length times `scale`.
Scene corner(float scale, glm::vec3 albedo = glm::vec3(0.8f), float znear = 0.05f,
             float zfar = 100.0f) {
  Builder b(albedo);
  const glm::mat4 S = glm::scale(glm::mat4(1.0f), glm::vec3(scale));
  b.quad(S * kFloor, 20.0f);
  b.quad(S * kWall, 20.0f);
  b.sun();
  b.s.lengthScale = scale;
  return b.camera(glm::vec3(2.5f, 1.6f, 0.0f) * scale, glm::vec3(0.0f), znear * scale,
                  zfar * scale);
}

// The corner lit only by a spot light pointing away from every surface: its reflective shadow
// map is black (an empty CDF for VPL sampling) and its shadow map empty.
Scene lightFacingAway() {
  Builder b;
  b.quad(kFloor, 20.0f);
  b.quad(kWall, 20.0f);
  Light l;
  l.type = LightType::Spot;
  l.intensity = 50.0f;
  l.outerConeAngle = glm::radians(20.0f);
  b.s.lights.push_back(l);
  // Up and away from the wall (x = 0): every ray of the 20-degree cone climbs and leaves it.
  const glm::vec3 at(1, 1, 0), dir = glm::normalize(glm::vec3(1, 1, 0));
  b.s.nodes[b.s.addNode("spot", glm::inverse(glm::lookAt(at, at + dir, glm::vec3(0, 0, 1))))]
      .light = 0;
  return b.camera(glm::vec3(2.5f, 1.6f, 0.0f), glm::vec3(0.0f));
}

// Six inward-facing quads around the origin (a closed box of half size 1), white, a point light
// inside: no sky is visible and every direction is occluded at a finite distance.
Scene closedBox() {
  Builder b(glm::vec3(1.0f));
  const glm::mat4 faces[] = {translate({0, 0, -1}),
                             translate({0, 0, 1}) * rotate(180.0f, {0, 1, 0}),
                             translate({-1, 0, 0}) * rotate(90.0f, {0, 1, 0}),
                             translate({1, 0, 0}) * rotate(-90.0f, {0, 1, 0}),
                             translate({0, -1, 0}) * rotate(-90.0f, {1, 0, 0}),
                             translate({0, 1, 0}) * rotate(90.0f, {1, 0, 0})};
  for (const glm::mat4& f : faces) b.quad(f, 1.0f);
  Light l;
  l.type = LightType::Point;
  l.intensity = 2.0f;
  b.s.lights.push_back(l);
  b.s.nodes[b.s.addNode("bulb", translate({0, 0.6f, 0}))].light = 0;
  return b.camera(glm::vec3(0.7f, 0.3f, 0.8f), glm::vec3(-1, -0.6f, -1));
}

// Slabs of thickness 1e-3 standing on a floor: a front and a back face 1e-3 apart.
Scene thinSlabs() {
  Builder b;
  b.quad(kFloor, 20.0f);
  for (int i = 0; i < 4; ++i) {
    const glm::mat4 at = translate({-1.5f + i, 0.5f, -0.5f * i});
    b.quad(at, 0.5f);
    b.quad(at * translate({0, 0, -1e-3f}) * rotate(180.0f, {0, 1, 0}), 0.5f);
  }
  b.sun();
  return b.camera(glm::vec3(0.5f, 1.2f, 3.0f), glm::vec3(0, 0.3f, -1));
}

// Occluders at distance 0: a quad lying exactly on the floor (coplanar, z-fighting), a wall
// whose lower edge touches the floor, a box corner.
Scene contactOccluders() {
  Builder b;
  b.quad(kFloor, 20.0f);
  b.quad(translate({0.5f, 0, 0}) * kFloor, 0.5f);  // coplanar with the floor
  b.quad(translate({-0.5f, 0.5f, -0.5f}), 0.5f);   // touches the floor along y = 0
  b.quad(translate({-1.0f, 0.5f, 0}) * kWall, 0.5f);
  b.sun();
  return b.camera(glm::vec3(0.3f, 1.5f, 2.0f), glm::vec3(0, 0, -0.2f));
}

// A wall far behind an open book of two 0.4-wide pages 3 units in front of it.
Scene depthDiscontinuity() {
  Builder b;
  b.quad(glm::mat4(1.0f), 10.0f);
  const glm::mat4 at = translate({0, 0, 3});
  b.quad(at * rotate(-45.0f, {0, 1, 0}) * translate({0.2f, 0, 0}), 0.2f);
  b.quad(at * rotate(45.0f, {0, 1, 0}) * translate({-0.2f, 0, 0}), 0.2f);
  b.sun(glm::vec3(0.2f, 0.5f, 1.0f));
  return b.camera(glm::vec3(0, 0, 6), glm::vec3(0));
}

// A huge floor seen from 1 cm above it, looking along it: every pixel grazes.
Scene grazing() {
  Builder b;
  b.quad(kFloor, 1000.0f);
  b.sun();
  return b.camera(glm::vec3(0, 0.01f, 0), glm::vec3(0, 0.01f, -10), 1e-4f, 1e5f);
}

// Looking straight up from under a floor that faces away: sky in every pixel.
Scene skyOnly() {
  Builder b;
  b.quad(translate({0, -1, 0}) * kFloor, 5.0f);
  b.sun();
  return b.camera(glm::vec3(0, 0, 0), glm::vec3(0, 1, 0.001f));
}

// A skinned quad over a floor, skinned to two joints, joint 1 scaled to zero. Vertices: no
// weights, weights that do not sum to 1, only the collapsed joint, the two mixed.
Scene degenerateSkin() {
  Builder b;
  b.quad(kFloor, 20.0f);
  Mesh m = quadMesh(1.0f);
  m.joints = {glm::uvec4(0), glm::uvec4(0, 1, 0, 0), glm::uvec4(1, 0, 0, 0),
              glm::uvec4(0, 1, 0, 0)};
  m.weights = {glm::vec4(0), glm::vec4(3, 1, 0, 0), glm::vec4(1, 0, 0, 0),
               glm::vec4(0.25f, 0.25f, 0, 0)};
  const int root = b.mesh(std::move(m), translate({0, 1, 0}));
  b.s.nodes[root].skin = 0;
  const int j0 = b.s.addNode("joint0", translate({0, 0.5f, 0}));
  const int j1 = b.s.addNode("joint1", glm::scale(glm::mat4(1.0f), glm::vec3(0.0f)));
  b.s.skins.push_back({"skin", {j0, j1}, {glm::mat4(1.0f), glm::mat4(1.0f)}});
  b.sun();
  return b.camera(glm::vec3(0.5f, 1.5f, 3.0f), glm::vec3(0, 0.8f, 0));
}

// Degenerate triangles (repeated vertices, collinear vertices) among normal ones, on a floor.
Scene zeroAreaTriangles() {
  Builder b;
  b.quad(kFloor, 20.0f);
  Mesh m = quadMesh(0.5f);
  m.vertices.push_back({glm::vec3(0.0f, 0.0f, 0.0f), glm::vec3(0, 0, 1), glm::vec2(0)});
  m.indices.insert(m.indices.end(), {0, 0, 0, 0, 2, 4, 1, 1, 3});  // points and a line
  m.triangleAreas.insert(m.triangleAreas.end(), {0.0f, 0.0f, 0.0f});
  b.mesh(std::move(m), translate({0, 0.5f, 0}));
  b.sun();
  return b.camera(glm::vec3(0.3f, 1.0f, 2.0f), glm::vec3(0, 0.4f, 0));
}

// Vertex normals of length zero (a model without normals that escaped the loader's repair).
Scene zeroNormals() {
  Builder b;
  b.quad(kFloor, 20.0f);
  b.mesh(quadMesh(0.5f, glm::vec3(0.0f)), translate({0, 0.5f, 0}));
  b.mesh(quadMesh(0.5f, glm::vec3(0.0f)), translate({0.6f, 0.5f, -0.5f}) * kWall);
  b.sun();
  return b.camera(glm::vec3(0.3f, 1.0f, 2.0f), glm::vec3(0, 0.4f, 0));
}

// ---- Checks -------------------------------------------------------------------------------------

std::string format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

// Largest |b - a| / max(1, |a|) over the pixels of two images of one resource.
double relativeChange(const ImageRGBA32F& a, const ImageRGBA32F& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i)
    worst = std::max(worst, std::abs(double(b.pixels[i]) - a.pixels[i]) /
                                std::max(1.0, std::abs(double(a.pixels[i]))));
  return worst;
}

}  // namespace

std::vector<HardCase> hardCases() {
  return {
      {"grazing_plane", "every pixel grazes a plane; near 1e-4, far 1e5", grazing},
      {"contact_occluder", "occluders at distance 0: coplanar and touching quads",
       contactOccluders},
      {"albedo_0", "black surfaces (no bounce, no sender radiance)",
       [] { return corner(1.0f, glm::vec3(0.0f)); }},
      {"albedo_1", "white surfaces (a bounce as bright as its sender)",
       [] { return corner(1.0f, glm::vec3(1.0f)); }},
      {"closed_box", "a closed white box with a light inside: no sky anywhere", closedBox},
      {"thin_slabs", "slabs 1e-3 thick: front and back faces one depth apart", thinSlabs},
      {"depth_discontinuity", "an open book 3 units in front of a wall", depthDiscontinuity},
      {"near_far_extreme", "the corner with near 1e-4 and far 1e5",
       [] { return corner(1.0f, glm::vec3(0.8f), 1e-4f, 1e5f); }},
      {"near_orthographic", "the corner through a 0.05-degree field of view from 3 km",
       [] {
         Scene s = corner(1.0f);
         s.cameras[0].yfov = glm::radians(0.05f);
         s.cameras[0].znear = 2000.0f;
         s.cameras[0].zfar = 5000.0f;
         const glm::vec3 dir = glm::normalize(glm::vec3(2.5f, 1.6f, 0.0f));
         s.nodes[s.activeCameraNode].local =
             glm::inverse(glm::lookAt(dir * 3000.0f, glm::vec3(0), glm::vec3(0, 1, 0)));
         s.updateWorldTransforms();
         return s;
       }},
      {"scale_1e-3", "the corner at scale 1e-3 (lengthScale 1e-3)", [] { return corner(1e-3f); }},
      {"scale_1e4", "the corner at scale 1e4 (lengthScale 1e4)", [] { return corner(1e4f); }},
      {"sky_only", "nothing but sky in the view", skyOnly},
      {"light_facing_away", "the only light points into the sky: a black RSM, no VPL flux",
       lightFacingAway},
      {"degenerate_skin", "zero weights, weights off 1, a joint scaled to 0", degenerateSkin},
      {"zero_area_triangles", "triangles that are points and lines", zeroAreaTriangles},
      {"zero_normals", "vertex normals of length 0", zeroNormals},
  };
}

void checkTexture(const std::string& name, const ImageRGBA32F& image, HardCaseRun& run) {
  size_t bad = 0;
  int firstBad = -1;
  for (size_t i = 0; i < image.pixels.size(); ++i)
    if (!std::isfinite(image.pixels[i]) && bad++ == 0) firstBad = int(i);
  run.values += image.pixels.size();
  run.nonFinite += bad;
  const int w = std::max(image.width, 1);
  if (bad)
    run.problems.push_back(format("'%s': %zu NaN/Inf values (first at pixel %d,%d channel %d)",
                                  name.c_str(), bad, (firstBad / 4) % w, (firstBad / 4) / w,
                                  firstBad % 4));
  // Documented ranges (gi/effect.h resources): channels checked, bounds.
  int channels = 0;
  float lo = 0.0f, hi = INFINITY;
  if (name == resources::kAO)
    channels = 1, hi = 1.0f;
  else if (name == resources::kDepth)
    channels = 1, hi = 1.0f;
  else if (name == resources::kLit || name == resources::kAmbient || name == resources::kIndirect ||
           name == "gbuffer.emission")
    channels = 3;
  else if (name == "gbuffer.albedo" || name == "gbuffer.material")
    channels = 3, hi = 1.0f;
  size_t out = 0;
  float worst = 0.0f;
  for (size_t p = 0; p + 3 < image.pixels.size(); p += 4)
    for (int c = 0; c < channels; ++c) {
      const float v = image.pixels[p + c];
      if (std::isfinite(v) && (v < lo || v > hi)) {
        if (out++ == 0) worst = v;
        if (std::abs(v - std::clamp(v, lo, hi)) > std::abs(worst - std::clamp(worst, lo, hi)))
          worst = v;
      }
    }
  if (out)
    run.problems.push_back(format("'%s': %zu values outside [%g, %g] (worst %g)", name.c_str(), out,
                                  double(lo), double(hi), double(worst)));
}

std::vector<HardCaseRun> runHardCases(vk::Context& ctx, const EffectRegistry& registry,
                                      const HardCaseOptions& options,
                                      const std::function<void(const HardCaseRun&)>& progress) {
  std::vector<std::string> effects = options.effects;
  if (effects.empty()) {
    effects = registry.names();
    effects.push_back("none");
  }
  for (const std::string& e : effects)
    if (e != "none" && !registry.has(e))
      throw Error(ErrorKind::Usage, "", "hard cases: unknown effect '" + e + "'");
  std::vector<HardCase> cases = hardCases();
  if (!options.cases.empty()) {
    std::vector<HardCase> chosen;
    for (const std::string& name : options.cases) {
      auto it = std::find_if(cases.begin(), cases.end(), [&](auto& c) { return c.name == name; });
      if (it == cases.end())
        throw Error(ErrorKind::Usage, "", "hard cases: unknown case '" + name + "'");
      chosen.push_back(*it);
    }
    cases = std::move(chosen);
  }

  // Every --set names the engine or an effect that runs, and a key and value it takes: checked
  // now through the frame set-up every run uses, so none is dropped or fails half-way.
  const Scene sample = cases.front().build();
  for (const std::string& set : options.sets) {
    const std::string owner = set.substr(0, set.find('.'));
    if (owner != kEngineSettingsOwner &&
        std::find(effects.begin(), effects.end(), owner) == effects.end())
      throw Error(ErrorKind::Usage, "--set",
                  "'" + set + "': '" + owner + "' is neither 'engine' nor an effect of the sweep");
    RenderRequest check;
    check.overrides.effects = owner == kEngineSettingsOwner ? std::vector<std::string>{}
                                                            : std::vector<std::string>{owner};
    check.overrides.sets = {set};
    configureRender(sample, registry, check);
  }

  Environment map;
  if (!options.environmentMap.empty()) loadEnvironmentMap(map, options.environmentMap);

  // Every pipeline made for the sweep counts its guards; the context's setting is restored.
  vk::GuardCounters& guards = ctx.guards();
  struct Restore {
    vk::GuardCounters& g;
    bool was;
    ~Restore() { g.setEnabled(was); }
  } restore{guards, guards.enabled()};
  guards.setEnabled(true);

  std::vector<HardCaseRun> runs;
  for (const HardCase& hc : cases) {
    Scene scene = hc.build();
    if (!options.environmentMap.empty()) scene.environment = map;
    for (const std::string& effect : effects) {
      const auto start = std::chrono::steady_clock::now();
      HardCaseRun run{hc.name, effect};
      EffectOverrides ov;
      ov.effects = effect == "none" ? std::vector<std::string>{} : std::vector{effect};
      // The engine's settings, and those of the effect that runs (the others' are refused).
      for (const std::string& set : options.sets)
        if (set.rfind(effect + ".", 0) == 0 ||
            set.rfind(kEngineSettingsOwner + std::string("."), 0) == 0)
          ov.sets.push_back(set);
      RenderSettings base;
      base.width = options.width;
      base.height = options.height;
      base.shadowMapSize = 256;
      base.aliasTransients = false;  // each transient keeps its own last version
      const RenderSettings rs = configureRender(scene, registry, {.overrides = ov}, base);
      guards.reset();
      Renderer r(ctx, scene, rs, &registry);
      for (int i = 0; i < std::max(options.warmupFrames, 1); ++i) r.renderFrame();
      for (const Renderer::NamedTexture& t : r.readAllTextures()) {
        if (t.name == resources::kGBuffer) {  // packed: checked channel by channel, unpacked
          const std::vector<uint8_t> packed = r.readTargetBytes(t.name);
          for (size_t c = 0; c < gbuffer::kChannels.size(); ++c) {
            ++run.textures;
            checkTexture(std::string("gbuffer.") + gbuffer::kChannels[c],
                         gbuffer::unpackChannel(packed, int(rs.width), int(rs.height), c), run);
          }
          continue;
        }
        if (!t.decoded) {
          ++run.undecoded;
          continue;
        }
        ++run.textures;
        checkTexture(t.name, t.image, run);
        if (t.name == resources::kDepth) {
          size_t sky = 0;
          for (size_t p = 0; p < t.image.pixels.size(); p += 4) sky += t.image.pixels[p] <= 0.0f;
          run.skyFraction = double(sky) / double(std::max<size_t>(1, t.image.pixels.size() / 4));
        }
      }
      run.guards = guards.read();  // the warm-up frames' (the read-backs waited for them)
      // Buffers: the vertices the skinning pass deformed.
      for (const Renderer::DeformedMesh& m : r.readDeformedMeshes()) {
        size_t bad = 0;
        for (const Vertex& v : m.vertices)
          for (int c = 0; c < 3; ++c)
            bad += !std::isfinite(v.position[c]) || !std::isfinite(v.normal[c]);
        run.values += m.vertices.size() * 6;
        run.nonFinite += bad;
        if (bad)
          run.problems.push_back(format("deformed mesh %d: %zu NaN/Inf values", m.mesh, bad));
      }
      if (options.flickerFrames > 1) {
        std::vector<std::string> watched = {resources::kLit};
        const std::vector<std::string> names = r.viewNames();
        if (std::count(names.begin(), names.end(), resources::kAO))
          watched.push_back(resources::kAO);
        std::vector<ImageRGBA32F> last;
        for (const auto& n : watched) last.push_back(r.readTarget(n));
        run.flicker = 0.0;
        for (int f = 1; f < options.flickerFrames; ++f) {
          r.renderFrame();
          for (size_t k = 0; k < watched.size(); ++k) {
            ImageRGBA32F now = r.readTarget(watched[k]);
            run.flicker = std::max(run.flicker, relativeChange(last[k], now));
            last[k] = std::move(now);
          }
        }
        if (run.flicker > kFlickerTolerance)
          run.problems.push_back(format("flicker %g over %d static frames (tolerance %g)",
                                        run.flicker, options.flickerFrames, kFlickerTolerance));
      }
      run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (progress) progress(run);
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

std::string guardSummary(const std::vector<vk::GuardCounters::Count>& guards) {
  std::string s;
  for (const vk::GuardCounters::Count& c : guards)
    for (uint32_t k = 0; k < vk::GuardCounters::kKinds; ++k)
      if (c.fired[k] > 0)
        s += (s.empty() ? "" : ", ") + c.pipeline + " " + vk::GuardCounters::kindName(k) + " " +
             std::to_string(c.fired[k]);
  return s;
}

}  // namespace gi::bench
