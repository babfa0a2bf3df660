// Light records and shadow-map planning (see light_setup.h).
#include "light_setup.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/errors.h"

namespace gi {
namespace {

// Plans the shadow map of one light: its views (1, or 6 cube faces in a 3x2 atlas) fitted to
// the scene bounds. Returns false when the light cannot see the scene (nothing to render).
bool addShadowMap(const Light& l, const glm::mat4& world, uint32_t lightIndex,
                  const glm::vec3& bmin, const glm::vec3& bmax, const CameraView& camera,
                  uint32_t res, std::vector<GpuShadowView>& out, std::vector<ShadowMap>& maps) {
  const glm::mat4 invView = glm::inverse(camera.view);
  const glm::vec3 pos = glm::vec3(world * glm::vec4(0, 0, 0, 1));
  const glm::vec3 dir = safeNormalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)), {0, -1, 0});
  std::array<glm::vec3, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[i] =
        glm::vec3(i & 1 ? bmax.x : bmin.x, i & 2 ? bmax.y : bmin.y, i & 4 ? bmax.z : bmin.z);
  ShadowMap map;
  map.light = lightIndex;
  map.firstView = uint32_t(out.size());
  auto addView = [&](const glm::mat4& viewProj, const glm::vec4& params, glm::uvec2 offset) {
    map.views.push_back({viewProj, VkRect2D{{int32_t(offset.x), int32_t(offset.y)}, {res, res}}});
    out.push_back({viewProj * invView, params, glm::vec4(offset.x, offset.y, res, 0.0f)});
  };
  if (l.type == LightType::Directional) {
    // Orthographic, fitted to the light-space bounds of the scene's box.
    const glm::vec3 centre = 0.5f * (bmin + bmax);
    const float radius = std::max(0.5f * glm::length(bmax - bmin), 1e-3f);
    const glm::mat4 view = lookAlong(centre - dir * (2.0f * radius), dir);
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const glm::vec3& c : corners) {
      const glm::vec3 v = glm::vec3(view * glm::vec4(c, 1.0f));
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    const float margin = 0.01f * radius;
    lo -= margin;
    hi += margin;
    const float znear = std::max(-hi.z, 1e-4f), zfar = -lo.z;
    const float extent = std::max(hi.x - lo.x, hi.y - lo.y);
    const glm::mat4 proj = orthoReverseZ(lo.x, lo.x + extent, lo.y, lo.y + extent, znear, zfar);
    map.width = map.height = res;
    addView(proj * view, glm::vec4(0.0f, znear, zfar, extent / float(res)), {0, 0});
  } else {
    // Perspective from the light's position; far: the farthest corner (or the range).
    float zfar = 0.0f;
    for (const glm::vec3& c : corners) zfar = std::max(zfar, glm::length(c - pos));
    if (l.range > 0.0f) zfar = std::min(zfar, l.range);
    if (!(zfar > 0.0f)) return false;
    zfar *= 1.01f;
    const float znear = std::max(zfar * 1e-3f, 0.01f);
    if (znear >= zfar) return false;
    if (l.type == LightType::Spot) {
      const float fov =
          std::min(2.0f * l.outerConeAngle + glm::radians(2.0f), glm::radians(170.0f));
      const glm::mat4 view = lookAlong(pos, dir);
      map.width = map.height = res;
      addView(perspectiveReverseZ(fov, 1.0f, znear, zfar) * view,
              glm::vec4(1.0f, znear, zfar, 2.0f * std::tan(0.5f * fov) / float(res)), {0, 0});
    } else {
      // Cube faces +x, -x, +y, -y, +z, -z (the order lighting.comp picks them in).
      const glm::vec3 axes[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                 {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
      const glm::mat4 proj = perspectiveReverseZ(glm::radians(90.0f), 1.0f, znear, zfar);
      map.width = 3 * res;
      map.height = 2 * res;
      for (uint32_t f = 0; f < 6; ++f)
        addView(proj * lookAlong(pos, axes[f]), glm::vec4(1.0f, znear, zfar, 2.0f / float(res)),
                {(f % 3) * res, (f / 3) * res});
    }
  }
  maps.push_back(std::move(map));
  return true;
}

}  // namespace

uint32_t LightSetup::layerWidth() const {
  uint32_t w = 1;
  for (const ShadowMap& m : maps) w = std::max(w, m.width);
  return w;
}

uint32_t LightSetup::layerHeight() const {
  uint32_t h = 1;
  for (const ShadowMap& m : maps) h = std::max(h, m.height);
  return h;
}

bool LightSetup::sameLayout(const LightSetup& o) const {
  if (lights.size() != o.lights.size() || maps.size() != o.maps.size()) return false;
  for (size_t i = 0; i < maps.size(); ++i)
    if (maps[i].light != o.maps[i].light || maps[i].views.size() != o.maps[i].views.size() ||
        maps[i].width != o.maps[i].width || maps[i].height != o.maps[i].height)
      return false;
  return true;
}

LightSetup planLights(const Scene& scene, const std::vector<Node>& nodes, const CameraView& camera,
                      const glm::vec3& bmin, const glm::vec3& bmax, uint32_t shadowMapSize) {
  LightSetup out;
  out.cameraInvView = glm::inverse(camera.view);
  const bool hasBounds = bmin.x <= bmax.x;
  for (const Node& node : nodes) {
    if (node.light < 0 || size_t(node.light) >= scene.lights.size()) continue;
    const Light& l = scene.lights[node.light];
    GpuLight g{};
    glm::vec3 pos = glm::vec3(camera.view * node.world * glm::vec4(0, 0, 0, 1));
    glm::vec3 dir = glm::vec3(camera.view * node.world * glm::vec4(0, 0, -1, 0));
    float type = l.type == LightType::Directional ? 0.0f : l.type == LightType::Point ? 1.0f : 2.0f;
    g.positionRange = glm::vec4(pos, std::max(l.range, 0.0f));
    g.directionType = glm::vec4(dir, type);
    g.radiance = glm::vec4(l.color * std::max(l.intensity, 0.0f), 0.0f);
    g.cone = glm::vec4(std::cos(l.innerConeAngle), std::cos(l.outerConeAngle), 0, 0);
    g.shadow = glm::vec4(-1.0f, 0.0f, 0.0f, 0.0f);
    LightInfo info;
    info.type = l.type;
    info.position = glm::vec3(node.world * glm::vec4(0, 0, 0, 1));
    info.direction = glm::vec3(node.world * glm::vec4(0, 0, -1, 0));
    const float len = glm::length(info.direction);
    info.direction =
        len > 1e-20f && std::isfinite(len) ? info.direction / len : glm::vec3(0, -1, 0);
    info.radiance = glm::vec3(g.radiance);
    info.range = g.positionRange.w;
    info.cosInner = g.cone.x;
    info.cosOuter = g.cone.y;
    info.index = uint32_t(out.lights.size());
    if (l.castsShadows && hasBounds) {
      const float first = float(out.views.size());
      if (addShadowMap(l, node.world, uint32_t(out.lights.size()), bmin, bmax, camera,
                       shadowMapSize, out.views, out.maps))
        g.shadow = glm::vec4(first, std::max(l.shadowBias.constant, 0.0f),
                             std::max(l.shadowBias.slope, 0.0f), float(out.maps.size() - 1));
    }
    info.shadowLayer = int(g.shadow.x) >= 0 ? int(g.shadow.w) : -1;
    out.lights.push_back(g);
    out.world.push_back(info);
  }
  return out;
}

void ShadowFitBounds::update(const glm::vec3& lo, const glm::vec3& hi) {
  const bool inside =
      glm::all(glm::greaterThanEqual(lo, lo_)) && glm::all(glm::lessThanEqual(hi, hi_));
  const bool shrunk = glm::any(glm::lessThan(2.0f * (hi - lo), hi_ - lo_));
  if (!fitted_) {
    lo_ = lo;
    hi_ = hi;
  } else if (!inside || shrunk) {
    const glm::vec3 margin = 0.125f * (hi - lo);
    lo_ = lo - margin;
    hi_ = hi + margin;
  }
  fitted_ = true;
}

void checkLightLimits(const LightSetup& next, const VkPhysicalDeviceLimits& limits) {
  auto refuse = [](const std::string& message) {
    throw Error(ErrorKind::Unsupported, "", message);
  };
  if (next.lights.size() > kMaxLights)
    refuse(std::to_string(next.lights.size()) + " lights exceed the engine's " +
           std::to_string(kMaxLights));
  if (next.views.size() > kMaxShadowViews)
    refuse(std::to_string(next.views.size()) + " shadow views exceed the engine's " +
           std::to_string(kMaxShadowViews) +
           " (a point light takes six, any other light one: cast fewer shadows)");
  if (next.layerWidth() > limits.maxImageDimension2D ||
      next.layerHeight() > limits.maxImageDimension2D)
    refuse("shadow maps of " + std::to_string(next.layerWidth()) + "x" +
           std::to_string(next.layerHeight()) + " texels exceed the device's " +
           std::to_string(limits.maxImageDimension2D) +
           " (a point light's six faces take 3x2 maps: lower engine.shadow_map_size)");
  if (next.maps.size() > limits.maxImageArrayLayers)
    refuse(std::to_string(next.maps.size()) + " shadow-casting lights exceed the device's " +
           std::to_string(limits.maxImageArrayLayers) + " shadow-map layers");
}

LightBuffers::LightBuffers(vk::Context& ctx)
    : lights_(ctx, kMaxLights * sizeof(GpuLight), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true),
      shadowViews_(ctx, kMaxShadowViews * sizeof(GpuShadowView), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                   true) {}

void LightBuffers::writeShadowView(uint32_t index, const GpuShadowView& view) {
  if (index < kMaxShadowViews)
    shadowViews_.write(&view, sizeof view, size_t(index) * sizeof(GpuShadowView));
}

void LightBuffers::upload(const LightSetup& setup) {
  if (!setup.lights.empty())
    lights_.write(setup.lights.data(), setup.lights.size() * sizeof(GpuLight));
  if (!setup.views.empty())
    shadowViews_.write(setup.views.data(), setup.views.size() * sizeof(GpuShadowView));
}

}  // namespace gi
