// Obscurance and the ambient transfer function (Umenhoffer, Toth, Szirmay-Kalos; seed 001):
// containment tests of Lloyd-relaxed, cos x mu' importance-sampled points against the depth
// buffer, the silhouette test, 4x4 interleaving and a depth-aware 4x4 box filter. Publishes
// "ao": obscurance O (transfer off) or the ambient transfer W (eq. 6/9), which the lighting pass
// multiplies into its environment term, i.e. L' = a W L^a (eq. 2). transfer = radiance
// publishes "ambient" instead: the ambient radiance with the occluders' direct radiance in
// colour (a pass `obscurance_radiance` sums the lights for them first). Estimator, guard and
// sample set: obscurance_kernel.h; measurements: README.md.
#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "gi/effect_registry.h"
#include "gi/effect_shader.h"
#include "gi/lit_surface.h"
#include "gi/screen_space_ao.h"
#include "gi/separable_dispatch.h"
#include "gi/setting_uniforms.h"
#include "obscurance.comp.h"         // const uint32_t obscurance_comp[]
#include "obscurance_filter.comp.h"  // const uint32_t obscurance_filter_comp[]
#include "obscurance_kernel.h"
#include "obscurance_radiance.comp.h"         // const uint32_t obscurance_radiance_comp[]
#include "obscurance_resolve.comp.h"          // const uint32_t obscurance_resolve_comp[]
#include "obscurance_resolve_ambient.comp.h"  // const uint32_t obscurance_resolve_ambient_comp[]

namespace {

namespace res = gi::resources;
namespace obs = gi::obscurance;
using gi::SettingType;

constexpr VkFormat kAOFormat = VK_FORMAT_R16_SFLOAT;
constexpr VkFormat kRadianceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;  // and "ambient"
// half2(N / n, D / n), 1 / distance, half2 slopes: what the filter reads, one fetch per tap.
constexpr VkFormat kSumsFormat = VK_FORMAT_R32G32B32A32_UINT;
constexpr uint32_t kGroupX = 32, kGroupY = 16;  // 32x16: llvmpipe's fastest
constexpr int kFilterRadius = 2;                // [.5 1 1 1 .5]: the 4x4 box

class ObscuranceEffect : public gi::Effect {
 public:
  // "ambient" and "direct_light" are written only with transfer = radiance, "ao" otherwise. Its
  // physical target is AO (equal to obscurance for membership step); what it estimates exactly
  // is estimatedQuantity().
  gi::EffectInfo info() const override {
    return {
        .name = "obscurance",
        .version = "1.0",
        .description =
            "obscurance with a fuzzy membership and the ambient transfer function "
            "with interreflections (seed 001)",
        .stage = gi::EffectStage::BeforeLighting,
        .reads = {res::kDepth, res::kGBuffer, res::kLights, res::kShadowViews, res::kShadowMaps},
        .writes = {res::kAO, res::kAmbient, res::kDirectLight},
        .debugView = res::kAO,
        .estimates = gi::GroundTruth::AmbientOcclusion,
        .range = "radius"};
  }

  // transfer off: obscurance with the membership setting (gi-reference --quantity obscurance
  // --membership <membership>). The W modes output W (interreflections with the occluders'
  // albedo or emission), which no reference computes: they declare AO of R, their physical
  // target, so both of gi-bench's columns are against AO. radiance replaces the ambient term
  // with light (the environment's and the lit neighbours' one bounce): the lit image against
  // direct + one diffuse bounce, as SSDO.
  gi::EstimatedQuantity estimatedQuantity(const gi::SettingValues& s) const override {
    gi::EstimatedQuantity q;
    q.radius = s.number("radius");
    if (s.option("transfer") == "off") {
      q.kind = gi::EstimatedQuantity::Kind::Obscurance;
      q.membership = s.option("membership");
    } else if (s.option("transfer") == "radiance") {
      q.kind = gi::EstimatedQuantity::Kind::DirectIndirect;
    } else {
      q.kind = gi::EstimatedQuantity::Kind::AmbientOcclusion;
    }
    return q;
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::aoRadiusSetting(
            "world-space radius R: the membership reaches 1 (fully open) at distance R"),
        gi::SettingDesc::enumeration(
            "membership", obs::membershipNames(), int(obs::Membership::Sqrt),
            "fuzzy membership mu(d / R) of an occluder at distance d: sqrt (Mendez et al.), "
            "step (ambient occlusion), linear, smoothstep"),
        gi::SettingDesc::samples("samples", 16, 1, obs::kMaxSamples,
                                 "rays per pixel (x 16 interleaved rotations after the filter)",
                                 true),
        {"points_per_ray", SettingType::Int, 1, 1, 2,
         "containment tests along each ray (seed 001: 1 or 2); 2 catches thin occluders", true},
        gi::SettingDesc::enumeration(
            "transfer", obs::transferNames(), int(obs::Transfer::Off),
            "output: off = obscurance O; albedo = ambient transfer W (interreflections with the "
            "occluders' albedo, eq. 9); emission = W with the occluders' emission (+ albedo x "
            "ambient), clamped to 1; radiance = the ambient radiance in colour (\"ambient\") "
            "with the occluders' direct radiance (emission + albedo x the lights): colour "
            "bleeding, W above 1",
            true),
        {"bias", SettingType::Float, 0.02, 0.0, 0.5,
         "a test point must be this far behind the depth buffer's surface to count as inside, "
         "as a fraction of R",
         false},
        {"filter", SettingType::Bool, 1, 0, 1,
         "depth-aware 4x4 box filter of the interleaved estimate", true},
        gi::interleaveSetting("rotate the sample set in a 4x4 pixel pattern (16 rotations) for the "
                              "filter to average"),
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "obscurance");
    using obs::Uniforms;
    const int mode = s.integer("transfer");
    filter_ = s.flag("filter");
    radiance_ = mode == int(obs::Transfer::Radiance);
    if (radiance_)
      radiancePipeline_ = gi::vk::Pipeline::compute(
          vk, gi::computeShader("obscurance: obscurance_radiance.comp", obscurance_radiance_comp));
    const gi::vk::BlockChecks params{
        {},
        {{"obs", GI_CPP_BLOCK(Uniforms, radius, bias, filterTolerance, guard, rotation, kernel)}}};
    main_ = gi::vk::Pipeline::compute(
        vk, gi::computeShader("obscurance: obscurance.comp", obscurance_comp,
                              {uint32_t(s.integer("samples")),
                               uint32_t(s.integer("points_per_ray")), uint32_t(mode)},
                              params));
    const std::vector<uint32_t> filterSpec = {uint32_t(mode),
                                              uint32_t(filter_ ? kFilterRadius : 0)};
    filterX_ = gi::vk::Pipeline::compute(
        vk, gi::computeShader("obscurance: obscurance_filter.comp", obscurance_filter_comp,
                              filterSpec, params));
    resolve_ = gi::vk::Pipeline::compute(
        vk, radiance_ ? gi::computeShader("obscurance: obscurance_resolve_ambient.comp",
                                          obscurance_resolve_ambient_comp, filterSpec, params)
                      : gi::computeShader("obscurance: obscurance_resolve.comp",
                                          obscurance_resolve_comp, filterSpec, params));
    uniforms_.prepare(
        vk, s, {"radius", "bias", "membership", "samples", "interleave"}, [](const auto& k) {
          return obs::makeUniforms(k[0], k[1], obs::Membership(int(k[2])), int(k[3]), k[4] != 0.0);
        });
    uniforms_.block().invalidate();  // the sample count may have changed
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::LitSurfaceInputs surface;  // transfer = radiance: what obscurance_radiance reads
      // `sent`: the occluders' radiance for transfer = radiance (obscurance_radiance), else depth
      // in its place (the other transfers read the occluders from the packed G-buffer).
      gi::TextureHandle depth, gbuffer, radiance, direct, sent, sums, half, out;
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    const VkBuffer frame = ctx.frameUniforms();
    const VkSampler nearest = ctx.nearestSampler();
    const bool radiance = radiance_;  // changesGraph: prepare() matched the transfer

    // transfer = radiance: the occluders' direct radiance, once per pixel, read by the taps in
    // place of the emission; and the lights' radiance as "direct_light" (the lighting pass then
    // does not sum them again).
    if (radiance)
      graph.addPass(
          "obscurance_radiance",
          [&](gi::PassBuilder& b) {
            io->surface.read(b, bb);
            io->radiance =
                b.write(b.create("obscurance_radiance", gi::TextureDesc{kRadianceFormat}),
                        gi::TextureUsage::StorageWrite);
            io->direct = b.write(b.create(res::kDirectLight, gi::TextureDesc{kRadianceFormat}),
                                 gi::TextureUsage::StorageWrite);
          },
          [this, io, frame, nearest](gi::PassContext& pc) {
            gi::vk::DescriptorWriter w(radiancePipeline_);
            w.buffer("Frame", frame);
            io->surface.bind(w, pc, nearest);
            w.image("outRadiance", pc.view(io->radiance)).image("outDirect", pc.view(io->direct));
            pc.dispatch(radiancePipeline_, w, pc.extent(io->radiance), kGroupX, kGroupY);
          });

    graph.addPass(
        "obscurance",
        [&](gi::PassBuilder& b) {
          io->depth = b.read(bb.texture(res::kDepth));
          io->gbuffer = b.read(bb.texture(res::kGBuffer));
          // MODE 3 reads the radiance pass's output; the other modes bind depth in its place.
          io->sent = radiance ? b.read(io->radiance) : io->depth;
          io->sums = b.write(b.create("obscurance_sums", gi::TextureDesc{kSumsFormat}),
                             gi::TextureUsage::StorageWrite);
        },
        [this, io, values = &settings, frame, nearest](gi::PassContext& pc) {
          // The sample set is rebuilt only when a setting it depends on changed.
          const VkBuffer params = uniforms_.upload(*values);
          gi::vk::DescriptorWriter w(main_);
          w.buffer("Frame", frame)
              .buffer("obs", params)
              .texture("gDepth", pc.view(io->depth), nearest)
              .texture("giGBuffer", pc.view(io->gbuffer), nearest)
              .texture("gRadiance", pc.view(io->sent), nearest)
              .image("outSums", pc.view(io->sums));
          const VkExtent2D e = pc.extent(io->sums);
          pc.dispatch(main_, w, e, kGroupX, kGroupY);
        });

    // Filter along x into `half`, then along y with the division into "ao"; without the filter
    // only the division (one dispatch).
    const bool filter = settings.flag("filter");  // changesGraph: prepare() matched it
    graph.addPass(
        "obscurance_filter",
        [&](gi::PassBuilder& b) {
          io->sums = b.read(io->sums);
          if (filter)
            io->half = b.write(b.create("obscurance_filter_x", gi::TextureDesc{kSumsFormat}),
                               gi::TextureUsage::StorageWrite);
          io->out = b.write(b.create(radiance ? res::kAmbient : res::kAO,
                                     gi::TextureDesc{radiance ? kRadianceFormat : kAOFormat}),
                            gi::TextureUsage::StorageWrite);
        },
        [this, io, frame, nearest, filter](gi::PassContext& pc) {
          gi::dispatchSeparable(pc,
                                {.x = filter ? &filterX_ : nullptr,
                                 .y = &resolve_,
                                 .input = "inSums",
                                 .output = "outImage",
                                 .sampler = nearest,
                                 .bind =
                                     [&](gi::vk::DescriptorWriter& w, const gi::vk::Pipeline&) {
                                       w.buffer("Frame", frame).buffer("obs", uniforms_.handle());
                                     },
                                 .groupX = kGroupX,
                                 .groupY = kGroupY},
                                io->sums, io->half, io->out);
        });
    bb.put(radiance ? res::kAmbient : res::kAO, io->out);
    if (radiance) bb.put(res::kDirectLight, io->direct);
  }

 private:
  gi::vk::Pipeline main_, filterX_, resolve_, radiancePipeline_;
  bool filter_ = true, radiance_ = false;
  gi::SettingUniforms<obs::Uniforms, 5> uniforms_;  // rewritten only when a setting changed
};

}  // namespace

GI_EFFECT_MODULE(ObscuranceEffect)
