// What an effect declares, and the Effect interface itself, without Vulkan: the configuration
// layer (registry, presets, settings resolution) and tools that only list or configure effects
// include this; the services an effect records passes with are in gi/effect.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gi/settings.h"

// Bumped whenever this header, effect.h, settings.h, frame_graph.h or the shader interface change
// in a way that breaks compiled modules; the registry refuses modules built against another value.
// 8: GpuScene::drawDepthFromBuffer (a new virtual: the vtable moved).
// 9: DepthAwareBlur gained its reduced-resolution upsample (its layout grew).
// 10: the packed G-buffer ("gbuffer", gbuffer.glsl); LitSurfaceInputs reads depth + gbuffer.
// 11: GpuScene::drawGBuffer takes an optional culling matrix.
// 12: vk::Pipeline holds its shader's reflected interface (bindings by name, checked blocks);
//     SettingValues stores values per declaration index (typed Setting<T> handles).
// 13: ImagePass gained `publish` (its layout grew).
// 14: litFilterInfo and addLitFilterPass (gi/image_pass.h), used by the template.
// 15: EffectContext::publishedRange (a new virtual), EffectInfo::range.
#define GI_EFFECT_ABI_VERSION 15u

namespace gi {

class EffectContext;  // gi/effect.h
class FrameGraph;     // gi/graph/frame_graph.h

// Well-known frame-graph resources, shared through the blackboard by these names.
namespace resources {
inline constexpr const char* kDepth = "depth";  // D32 reverse-Z (1 near, 0 far/sky)
// RGBA32UI packed normal, albedo, roughness, metallic, emission, geometry flag: read it through
// gbuffer.glsl (giGBufferLoad, giGBufferNormal, ...), never by its bits (gi/gbuffer.h).
inline constexpr const char* kGBuffer = "gbuffer";
inline constexpr const char* kMotion = "motion";  // RG16F current - previous, UV units
// The G-buffer's channels unpacked to RGBA32F, each by its own pass that runs only when the
// channel is viewed or read back (and for effects that have not moved to gbuffer.glsl).
inline constexpr const char* kNormal = "normal";      // view-space normal, w = 1 on geometry
inline constexpr const char* kAlbedo = "albedo";      // linear albedo, w = 1
inline constexpr const char* kMaterial = "material";  // roughness, metallic, 0, 1
inline constexpr const char* kEmission = "emission";  // linear radiance, w = 1
inline constexpr const char* kLit = "lit";            // RGBA16F lit image (linear HDR radiance)
// Optional inputs of the lighting pass (neutral when no effect publishes them; sample them with
// normalized coordinates: the neutral stand-in is 1x1). See "Lighting composition" in
// effects/README.md.
inline constexpr const char* kAO = "ao";  // R ambient visibility of the environment term, 1 = open
// RGBA16F: rgb the outgoing radiance of the environment term (albedo included), a = 1 where it
// replaces the engine's SH9 x albedo x AO term (directional occlusion), 0 to keep the engine's;
// a = 2: rgb is that radiance per unit diffuse albedo (irradiance / pi), and the lighting pass
// multiplies it by albedo x (1 - metallic), which it reads anyway (the effect need not).
inline constexpr const char* kAmbient = "ambient";
inline constexpr const char* kIndirect = "indirect";  // RGBA16F outgoing indirect radiance, added
// RGBA8 (any size, sampled bilinearly at the pixel's uv): channel i multiplies the shadow factor
// of the i-th shadow-casting light (the first four in `lights` order), 1 = no change.
inline constexpr const char* kContactShadow = "contact_shadow";
// RGBA16F (any size): the outgoing radiance of the scene's lights (diffuse + specular, shadowed,
// contact shadows applied), as sumLights in lights.glsl computes it, at every geometry pixel.
// When published it *replaces* the lighting pass's own evaluation of the lights: an effect that
// needs the direct light anyway (e.g. as the radiance of bounce senders) publishes it and the
// lights are evaluated once. It then owns the contact shadows (publishing both is an error).
inline constexpr const char* kDirectLight = "direct_light";
inline constexpr const char* kOutput = "output";  // RGBA8 tonemapped final image
inline constexpr const char* kFloor = "floor";    // RGBA8 cost-floor pass output
// Buffer: the point representation (gi/surface_points.h), two vec4 per point: world
// position + represented area, world normal + material index. Exists when an effect asked
// for points (EffectContext::requestSurfacePoints); re-evaluated from the deformed vertices
// in each frame after the pose changed (not when it did not), so points follow animated meshes.
inline constexpr const char* kSurfacePoints = "surface_points";
inline constexpr const char* kPointsView = "points";  // RGBA16F debug view of the points
// The environment (environment.glsl): equirect RGBA32F radiance map (Sky/Constant tabulated)
// and the std430 importance-sampling tables.
inline constexpr const char* kEnvironmentMap = "environment_map";
inline constexpr const char* kEnvironmentSampling = "environment_sampling";
}  // namespace resources

// When an effect's passes are added: before the lighting pass (it can feed lighting, e.g.
// AO) or after it (it can read the lit colour, e.g. an indirect bounce).
enum class EffectStage { BeforeLighting, AfterLighting };

// The physically meaningful target of an effect's output (EffectInfo::estimates): gi-bench
// reports the error against it beside the error against the quantity the effect declares it
// estimates exactly (Effect::estimatedQuantity).
enum class GroundTruth {
  DirectLight,       // the lit image against ray-traced direct light (the default)
  AmbientOcclusion,  // its "ao" resource against ray-traced AO of its `radius` setting
  IndirectLight,     // the lit image against direct light + one diffuse bounce
};

// Exactly what an effect's output estimates, with the parameters its current settings give
// (Effect::estimatedQuantity). Each kind is one quantity of the CPU reference renderer
// (gi/reference/reference.h, gi-reference --quantity), so gi-bench can render it with the same
// parameters. The AO-like kinds are read from the effect's "ao" resource, the lighting kinds
// from the lit image.
struct EstimatedQuantity {
  enum class Kind {
    AmbientOcclusion,  // binary AO of radius r, cosine-weighted (reference "ao")
    Obscurance,        // (1/pi) int mu(t(w)) cos dw, mu = membership reaching 1 at r
    Alchemy,           // max(0, 1 - I)^contrast, I the Alchemy integral (reference "alchemy")
    AlchemyDisk,       // max(0, 1 - I)^contrast, I the screen-disk Alchemy integral of eq. 10's
                       // taps (reference "alchemy-disk"; uses bias too)
    DirectLight,       // the lit image: direct light (reference "direct")
    DirectIndirect,    // the lit image: direct light + one diffuse bounce ("direct+indirect")
  };
  Kind kind = Kind::DirectLight;
  double radius = 0.5;              // r of AO, R of obscurance, r of Alchemy (world units)
  std::string membership = "sqrt";  // obscurance: sqrt, linear, smoothstep, step or exp
  // Alchemy (seed 003 eq. 10): falloff g(t) = sigma t / (max(u^2, t^2) + epsilon).
  double sigma = 1.0, u = 0.0, epsilon = 1e-4, contrast = 1.0;
  double bias = 0.0;  // AlchemyDisk: beta of the numerator max(0, v.n - beta z) (ABI 7)
};
// "obscurance(r=0.5, membership=linear)", "alchemy(r=0.5, sigma=1, u=0, epsilon=0.0001,
// contrast=1)", "alchemy-disk(r=0.5, sigma=1, u=0, epsilon=0.0001, contrast=1, bias=0.0001)",
// "ao(r=0.5)", "direct light", "direct+indirect light": the parameters the kind
// uses, nothing else (gi-render --list-effects, reports).
std::string describe(const EstimatedQuantity& q);

struct EffectInfo {
  std::string name;         // unique, lower case, used in scenes, presets, --effects and --view
  std::string version;      // the effect's own version
  std::string description;  // one line
  EffectStage stage = EffectStage::BeforeLighting;
  // Blackboard resources its passes look up and publish. Checked on every graph build: a lookup
  // or publication not declared here is an error naming the effect, and so is a declared write
  // it did not publish (unless it is an optional lighting input: ao, ambient, indirect,
  // contact_shadow, which the neutral fallback then replaces). Effects of one stage run in the
  // order these imply (a reader after the writer), whatever their order in the scene.
  std::vector<std::string> reads;
  std::vector<std::string> writes;
  std::string debugView;  // resource shown by `gi-render --view <name>`
  GroundTruth estimates = GroundTruth::DirectLight;
  // The world-length setting within which its outputs account for occluders and light (its
  // near field, e.g. an AO's or SSDO's "radius"); empty: unbounded. An effect that composes
  // with them reads it through EffectContext::publishedRange and leaves that range to them.
  std::string range;
};

class Effect {
 public:
  virtual ~Effect() = default;
  virtual EffectInfo info() const = 0;
  virtual std::vector<SettingDesc> settings() const = 0;
  // What the output estimates exactly for these (validated) settings. The default follows
  // info().estimates: AO of the `radius` setting (0.5 without one), direct + indirect light,
  // or direct light. Override it when the effect computes another quantity (obscurance, the
  // Alchemy integral, ...): gi-bench then scores it against that too. See effects/README.md.
  // An AO effect may declare a light kind for settings under which it outputs light itself
  // (gi-bench then judges its lit image as light); a light effect may not declare AO.
  virtual EstimatedQuantity estimatedQuantity(const SettingValues& settings) const {
    EstimatedQuantity q;
    switch (info().estimates) {
      case GroundTruth::AmbientOcclusion:
        q.kind = EstimatedQuantity::Kind::AmbientOcclusion;
        for (const SettingDesc& d : settings.descs())
          if (d.name == "radius") q.radius = settings.number("radius");
        break;
      case GroundTruth::IndirectLight:
        q.kind = EstimatedQuantity::Kind::DirectIndirect;
        break;
      case GroundTruth::DirectLight:
        q.kind = EstimatedQuantity::Kind::DirectLight;
        break;
    }
    return q;
  }
  // Creates pipelines and other long-lived objects; called again only when a setting marked
  // `changesGraph` changed. `settings` are validated against settings().
  virtual void prepare(EffectContext& ctx, const SettingValues& settings) = 0;
  // Declares the effect's passes (reads through the blackboard, publishes its outputs there).
  // Called on every graph compile. `settings` stays valid, and is updated in place by
  // uniform-only changes, until the next graph build: execute callbacks may keep a pointer.
  virtual void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues& settings) = 0;
  // Once per frame, after the pose, the camera and the main view's uniforms (frame()) of the
  // frame are known, before extra views are uploaded and passes recorded: move extra views
  // (ViewUniforms::setCamera) here.
  virtual void update(EffectContext& ctx, const SettingValues& settings) {
    (void)ctx;
    (void)settings;
  }
};

}  // namespace gi
