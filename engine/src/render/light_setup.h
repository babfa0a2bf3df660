// Lights and shadow maps for one pose of the scene: the GPU light records (camera view
// space) and the shadow views fitted to the scene's bounds. Re-planned whenever lights, the
// camera or the geometry move (Renderer::setTime).
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "gi/scene.h"
#include "gpu_types.h"

namespace gi {

inline constexpr uint32_t kMaxShadowMaps = 4;  // lighting.comp binds shadowMap0..3

// One shadow map (slot): rendered as one view, or six cube faces in a 3x2 atlas.
struct ShadowMap {
  uint32_t light = 0;  // index into the light records (names the pass "shadow_<light>")
  uint32_t width = 0, height = 0;
  struct View {
    glm::mat4 viewProj;  // world -> light clip
    VkRect2D rect;
  };
  std::vector<View> views;
};

struct LightSetup {
  std::vector<gpu::Light> lights;      // one per light node, in node order
  std::vector<gpu::ShadowView> views;  // every shadow map's views, in slot order
  std::vector<ShadowMap> maps;         // the first kMaxShadowMaps shadow-casting lights
  // Same slots, lights and view counts: only the buffers' contents change, not the graph.
  bool sameLayout(const LightSetup& o) const;
};

// `nodes`: the posed hierarchy (world transforms current); lights come from scene.lights.
// Bounds: world-space box of all geometry (empty box: no shadow maps).
LightSetup planLights(const Scene& scene, const std::vector<Node>& nodes, const CameraView& camera,
                      const glm::vec3& boundsMin, const glm::vec3& boundsMax,
                      uint32_t shadowMapSize);

}  // namespace gi
