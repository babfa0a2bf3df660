// Screen-space ambient occlusion (RTR 11.3.6; seed 001 §4.2-4.3): normal-oriented hemisphere
// taps tested against the depth buffer with a range check, 4x4 interleaved kernel rotations,
// and a depth-aware blur that removes the interleave pattern. Publishes "ao", which the
// lighting pass applies to the environment term. Estimator and kernel: ssao_kernel.h.
#include <algorithm>
#include <array>
#include <vector>

#include "gi/depth_aware_blur.h"
#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/uniform_block.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "ssao.comp.h"  // const uint32_t ssao_comp[]
#include "ssao_kernel.h"

namespace {

namespace res = gi::resources;
using gi::SettingType;

// Workgroup size of ssao.comp (local_size_x/y there). Large groups: on
// llvmpipe each workgroup carries a fixed scheduling cost, which 8x8 groups paid 3600 times at
// 640x360 (a quarter of the 64-tap pass); 32x16 measured fastest (32x32 loses cache locality).
constexpr uint32_t kGroupX = 32, kGroupY = 16;

class SsaoEffect : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    gi::EffectInfo i;
    i.name = "ssao";
    i.version = "1.0";
    i.description =
        "screen-space ambient occlusion (hemisphere taps, 4x4 interleave, "
        "depth-aware blur)";
    i.stage = gi::EffectStage::BeforeLighting;
    i.reads = {res::kDepth, res::kGBuffer};
    i.writes = {res::kAO};
    i.debugView = res::kAO;
    i.estimates = gi::GroundTruth::AmbientOcclusion;
    return i;
  }

  // Obscurance with the linear membership mu(d) = d / R (ssao_kernel.h: cosine-distributed
  // directions with distances uniform in [0, R] count a hit at d as occluding 1 - d / R of the
  // taps). Exact for intensity 1 (the default): AO = 1 - intensity x occluded fraction.
  gi::EstimatedQuantity estimatedQuantity(const gi::SettingValues& s) const override {
    gi::EstimatedQuantity q;
    q.kind = gi::EstimatedQuantity::Kind::Obscurance;
    q.radius = s.number("radius");
    q.membership = "linear";
    return q;
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::SettingDesc::length("radius", 0.5, 1e-6, 1e9,
                                "world-space radius R of the sampled hemisphere (a model loaded "
                                "without a scene file scales the default to its size)"),
        gi::SettingDesc::samples("samples", 16, 1, gi::ssao::kMaxSamples, "taps per pixel", false),
        {"bias", SettingType::Float, 0.025, 0.0, 0.5,
         "an occluder must be this far in front of a tap, as a fraction of the radius", false},
        {"intensity", SettingType::Float, 1.0, 0.0, 4.0,
         "AO = 1 - intensity x occluded fraction (clamped to [0, 1])", false},
        gi::DepthAwareBlur::radiusSetting(2),
        {"interleave", SettingType::Bool, 1, 0, 1,
         "rotate the kernel in a 4x4 pixel pattern (16 rotations) for the blur to average", false},
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& settings) override {
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "ssao");
    using gi::ssao::Uniforms;
    gi::vk::ComputeDesc desc{"ssao: ssao.comp", {std::begin(ssao_comp), std::end(ssao_comp)}};
    desc.blocks.uniforms = {
        {"ssao", gi::vk::cppBlock<Uniforms>(
                     "gi::ssao::Uniforms",
                     {GI_BLOCK_MEMBER(Uniforms, params), GI_BLOCK_MEMBER(Uniforms, counts),
                      GI_BLOCK_MEMBER(Uniforms, rotation), GI_BLOCK_MEMBER(Uniforms, kernel)})}};
    ssao_ = gi::vk::Pipeline::compute(vk, desc);
    // The blur radius is compiled into the blur (changesGraph: prepare runs again).
    if (settings.integer("blur_radius") > 0) blur_.prepare(ctx, settings.integer("blur_radius"));
    uniforms_.create(vk);
    radius_ = settings.handle<double>("radius");
    bias_ = settings.handle<double>("bias");
    intensity_ = settings.handle<double>("intensity");
    samples_ = settings.handle<int>("samples");
    interleave_ = settings.handle<bool>("interleave");
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    // changesGraph: fixed for this graph. Without a blur "ao" is the packed texture itself (its
    // red channel is the AO).
    const int blurRadius = settings.integer("blur_radius");
    // `settings` lives as long as the graph and is updated in place: uniform-only settings are
    // read (and uploaded) when the pass records, every frame.
    gi::TextureHandle ao =
        gi::DepthAwareBlur::addProducer(graph, ctx,
                                        {"ssao", &ssao_, "outAO", kGroupX, kGroupY,
                                         [this, values = &settings](gi::vk::DescriptorWriter& w) {
                                           upload(*values);
                                           w.buffer("ssao", uniforms_.handle());
                                         }},
                                        blurRadius > 0 ? "ssao_raw" : res::kAO);
    if (blurRadius > 0)
      ao = blur_.addPass(graph, ctx, "ssao_blur", ao, res::kAO,
                         [values = &settings, radius = radius_] {
                           return float(gi::ssao::kBlurDepthTolerance * (*values)[radius]);
                         });
    graph.blackboard().put(res::kAO, ao);
  }

 private:
  // The kernel and rotations are rebuilt only when a setting changed since the last upload.
  void upload(const gi::SettingValues& s) {
    const std::array<double, 5> key = {s[radius_], s[bias_], s[intensity_], double(s[samples_]),
                                       s[interleave_] ? 1.0 : 0.0};
    uniforms_.update(key, [&] {
      return gi::ssao::makeUniforms(key[0], key[1], key[2], int(key[3]), key[4] != 0.0);
    });
  }

  gi::vk::Pipeline ssao_;
  gi::DepthAwareBlur blur_;
  gi::UniformBlock<gi::ssao::Uniforms> uniforms_;
  gi::Setting<double> radius_, bias_, intensity_;  // typed handles, made in prepare()
  gi::Setting<int> samples_;
  gi::Setting<bool> interleave_;
};

}  // namespace

GI_EFFECT_MODULE(SsaoEffect)
