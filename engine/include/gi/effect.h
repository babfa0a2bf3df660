// The effect plugin API. An effect declares, in one place, its name and version, the
// resources it reads and writes, its typed settings, and the frame-graph passes it adds.
// Effects see only this header (and what it includes): never engine internals. The engine
// never names an effect.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gi/graph/frame_graph.h"
#include "gi/settings.h"

// Bumped whenever this header, settings.h, frame_graph.h or the shader interface change in a
// way that breaks compiled modules; the registry refuses modules built against another value.
#define GI_EFFECT_ABI_VERSION 3u

namespace gi {

namespace vk {
class Context;
}

// Well-known frame-graph resources, shared through the blackboard by these names.
namespace resources {
inline constexpr const char* kDepth = "depth";        // D32 reverse-Z (1 near, 0 far/sky)
inline constexpr const char* kNormal = "normal";      // RGBA16F view-space normal, w=1 geometry
inline constexpr const char* kAlbedo = "albedo";      // RGBA8 sRGB
inline constexpr const char* kMaterial = "material";  // RGBA8 roughness, metallic
inline constexpr const char* kEmission = "emission";  // RGBA16F linear radiance
inline constexpr const char* kMotion = "motion";      // RG16F current - previous, UV units
inline constexpr const char* kLit = "lit";            // RGBA16F direct lighting (linear HDR)
inline constexpr const char* kAO = "ao";              // R8/R16F ambient occlusion, 1 = open
inline constexpr const char* kOutput = "output";      // RGBA8 tonemapped final image
inline constexpr const char* kFloor = "floor";        // RGBA8 cost-floor pass output
// Buffer: the point representation (gi/surface_points.h), two vec4 per point: world
// position + represented area, world normal + material index. Exists when an effect asked
// for points (EffectContext::requestSurfacePoints); re-evaluated every frame from the
// deformed vertices, so points follow animated meshes.
inline constexpr const char* kSurfacePoints = "surface_points";
inline constexpr const char* kPointsView = "points";  // RGBA16F debug view of the points
}  // namespace resources

// When an effect's passes are added: before the lighting pass (it can feed lighting, e.g.
// AO) or after it (it can read the lit colour, e.g. an indirect bounce).
enum class EffectStage { BeforeLighting, AfterLighting };

// What an effect's output approximates: gi-bench compares it with that ground truth.
enum class GroundTruth {
  DirectLight,       // the lit image against ray-traced direct light (the default)
  AmbientOcclusion,  // its "ao" resource against ray-traced AO of its `radius` setting
  IndirectLight,     // the lit image against direct light + one diffuse bounce
};

struct EffectInfo {
  std::string name;         // unique, lower case, used in scenes, presets, --effects and --view
  std::string version;      // the effect's own version
  std::string description;  // one line
  EffectStage stage = EffectStage::BeforeLighting;
  std::vector<std::string> reads;   // well-known resources it reads
  std::vector<std::string> writes;  // resources it publishes on the blackboard
  std::string debugView;            // resource shown by `gi-render --view <name>`
  GroundTruth estimates = GroundTruth::DirectLight;
};

// Services the engine offers effects while they build and record their passes.
class EffectContext {
 public:
  virtual ~EffectContext() = default;
  virtual vk::Context& vulkan() = 0;
  // Per-frame uniforms (camera matrices, viewport, ...): `FrameUniforms` in gi/common.glsl.
  virtual VkBuffer frameUniforms() = 0;
  virtual VkSampler nearestSampler() = 0;  // clamp to edge
  virtual VkSampler linearSampler() = 0;   // clamp to edge
  virtual VkExtent2D outputExtent() = 0;
  // Asks for the point representation (resources::kSurfacePoints) with at least `count`
  // points; call from prepare(). The engine samples max(requests) points once per renderer.
  virtual void requestSurfacePoints(uint32_t count) = 0;
};

class Effect {
 public:
  virtual ~Effect() = default;
  virtual EffectInfo info() const = 0;
  virtual std::vector<SettingDesc> settings() const = 0;
  // Creates pipelines and other long-lived objects; called again only when a setting marked
  // `changesGraph` changed. `settings` are validated against settings().
  virtual void prepare(EffectContext& ctx, const SettingValues& settings) = 0;
  // Declares the effect's passes (reads through the blackboard, publishes its outputs there).
  // Called on every graph compile.
  virtual void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues& settings) = 0;
};

}  // namespace gi
