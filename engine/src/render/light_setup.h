// Lights and shadow maps for one pose of the scene: the GPU light records (camera view
// space) and the shadow views fitted to the scene's bounds. Re-planned whenever lights, the
// camera or the geometry move (Renderer::setTime).
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "gi/lights.h"
#include "gi/scene.h"
#include "gi/vk/resources.h"

namespace gi {

// One shadow map: one layer of the "shadow_maps" array (its slot), rendered as one view, or six
// cube faces in a 3x2 atlas.
struct ShadowMap {
  uint32_t light = 0;      // index into the light records (names the pass "shadow_<light>")
  uint32_t firstView = 0;  // its first record in LightSetup::views
  uint32_t width = 0, height = 0;
  struct View {
    glm::mat4 viewProj;  // world -> light clip
    VkRect2D rect;
  };
  std::vector<View> views;
};

struct LightSetup {
  std::vector<GpuLight> lights;      // one per light node, in node order
  std::vector<LightInfo> world;      // the same lights in world space
  std::vector<GpuShadowView> views;  // every shadow map's views, in slot order
  std::vector<ShadowMap> maps;       // one per shadow-casting light that sees the scene
  glm::mat4 cameraInvView{1.0f};     // camera view -> world: views[i].viewToClip's right factor
  uint32_t layerWidth() const;       // the array's layer size: the largest map
  uint32_t layerHeight() const;
  // Same slots, lights and view counts: only the buffers' contents change, not the graph.
  bool sameLayout(const LightSetup& o) const;
};

// `nodes`: the posed hierarchy (world transforms current); lights come from scene.lights.
// Bounds: world-space box of all geometry (empty box: no shadow maps).
LightSetup planLights(const Scene& scene, const std::vector<Node>& nodes, const CameraView& camera,
                      const glm::vec3& boundsMin, const glm::vec3& boundsMax,
                      uint32_t shadowMapSize);

// The box the shadow maps are fitted to: the posed geometry's bounds, kept while the geometry
// stays inside them, so that objects moving within the scene leave the still lights' views (and
// their cached maps) alone. When the geometry leaves the box, or has shrunk below half of it
// along an axis, the box is refitted with a margin of 1/8 of its size on each side. A scene
// that never moves keeps its exact bounds.
class ShadowFitBounds {
 public:
  void update(const glm::vec3& lo, const glm::vec3& hi);
  const glm::vec3& min() const { return lo_; }
  const glm::vec3& max() const { return hi_; }

 private:
  bool fitted_ = false;
  glm::vec3 lo_{0.0f}, hi_{0.0f};
};

// Throws gi::Error (Unsupported) naming the limit `setup` exceeds: the engine's (kMaxLights
// records, kMaxShadowViews views) or the device's (a shadow-map layer's size, the layer count).
void checkLightLimits(const LightSetup& setup, const VkPhysicalDeviceLimits& limits);

// The uniform buffers "lights" and "shadow_views", full size (the shaders declare fixed-size
// arrays), holding the last uploaded set-up.
class LightBuffers {
 public:
  explicit LightBuffers(vk::Context& ctx);
  void upload(const LightSetup& setup);
  // One shadow view record rewritten (a map kept with the views it was drawn with).
  void writeShadowView(uint32_t index, const GpuShadowView& view);
  const vk::Buffer& lights() const { return lights_; }
  const vk::Buffer& shadowViews() const { return shadowViews_; }

 private:
  vk::Buffer lights_, shadowViews_;
};

}  // namespace gi
