// The effect plugin API. An effect declares, in one place, its name and version, the
// resources it reads and writes, its typed settings (gi/effect_info.h), and the frame-graph
// passes it adds with the services below. Effects see only this header (and what it includes):
// never engine internals. The engine never names an effect.
#pragma once

#include <vulkan/vulkan.h>

#include <memory>
#include <vector>

#include "gi/effect_info.h"
#include "gi/frame_uniforms.h"
#include "gi/gpu_scene.h"
#include "gi/graph/frame_graph.h"
#include "gi/lights.h"

namespace gi {

namespace vk {
class Context;
}

// Camera uniforms of an extra view (EffectContext::createView): a FrameUniforms buffer the engine
// refreshes every frame (time, environment, light count from the main view) with this view's
// camera and extent. Lives as long as the effect holds it.
class ViewUniforms {
 public:
  virtual ~ViewUniforms() = default;
  virtual void setCamera(const CameraView& camera, VkExtent2D extent) = 0;
  virtual VkBuffer buffer() const = 0;
  virtual const FrameUniforms& current() const = 0;  // what the next frame uploads
};

// Services the engine offers effects while they build and record their passes.
class EffectContext {
 public:
  virtual ~EffectContext() = default;
  virtual vk::Context& vulkan() = 0;
  // Per-frame uniforms (camera matrices, viewport, ...): `FrameUniforms` in gi/common.glsl.
  virtual VkBuffer frameUniforms() = 0;
  virtual const FrameUniforms& frame() = 0;  // the main view's values for the coming frame
  virtual VkSampler nearestSampler() = 0;    // clamp to edge
  virtual VkSampler linearSampler() = 0;     // clamp to edge
  virtual VkExtent2D outputExtent() = 0;
  // Asks for the point representation (resources::kSurfacePoints) with at least `count`
  // points; call from prepare(). The engine samples max(requests) points once per renderer.
  virtual void requestSurfacePoints(uint32_t count) = 0;
  // The scene on the GPU: buffers and draws from any view (gi/gpu_scene.h).
  virtual GpuScene& scene() = 0;
  // Uniforms of an extra view with the main view's frame-wide values (gi::ViewUniforms).
  virtual std::shared_ptr<ViewUniforms> createView() = 0;
  virtual const CameraView& camera() = 0;              // the main camera of the current pose
  virtual const std::vector<LightInfo>& lights() = 0;  // world space, current pose
  // The world-space distance within which the output `resource` accounts for occluders and
  // light, as the effect that published it earlier in this graph build declares it (the value
  // of its EffectInfo::range setting); 0 when no effect published it or it declares no range.
  // An effect that composes with it (e.g. a far-field term beside a near-field AO) leaves that
  // range to it, so nothing is counted twice.
  virtual double publishedRange(const std::string& resource) = 0;
};

}  // namespace gi
