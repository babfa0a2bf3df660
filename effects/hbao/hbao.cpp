// Horizon-based ambient occlusion (Bavoil, Sainz and Dimitrov 2008): horizon search along
// screen directions with per-sample attenuation and an angle bias, 4x4 interleaved direction
// rotations and step jitter, and a depth-aware blur that removes the pattern. Publishes "ao".
// Estimator: hbao_params.h; settings: README.md.
#include <algorithm>
#include <array>
#include <vector>

#include "gi/depth_aware_blur.h"
#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/uniform_block.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "hbao.comp.h"  // const uint32_t hbao_comp[]
#include "hbao_params.h"

namespace {

namespace res = gi::resources;
using gi::SettingType;

constexpr uint32_t kGroupX = 32, kGroupY = 16;  // local_size of both shaders (32x16: llvmpipe)

class HbaoEffect : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    gi::EffectInfo i;
    i.name = "hbao";
    i.version = "1.0";
    i.description =
        "horizon-based ambient occlusion (Bavoil et al. 2008: attenuated horizons, angle bias, "
        "4x4 interleave, depth-aware blur)";
    i.stage = gi::EffectStage::BeforeLighting;
    i.reads = {res::kDepth, res::kGBuffer};
    i.writes = {res::kAO};
    i.debugView = res::kAO;
    // Declares AO of `radius` (the default estimatedQuantity): its own quantity (README: no
    // cosine term, elevations from the image plane, attenuation W(r) = 1 - r^2 / R^2 instead
    // of a hard cut at R, the angle bias) has no reference, so both columns are against AO.
    i.estimates = gi::GroundTruth::AmbientOcclusion;
    return i;
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::SettingDesc::length("radius", 0.5, 1e-6, 1e9,
                                "world-space radius R: samples farther than R are ignored, nearer "
                                "ones attenuated by 1 - r^2 / R^2"),
        gi::SettingDesc::samples(
            "directions", 6, 1, gi::hbao::kMaxDirections,
            "screen directions per pixel (rotated per pixel by the 4x4 interleave)", true),
        gi::SettingDesc::samples("steps", 4, 1, gi::hbao::kMaxSteps, "depth samples per direction",
                                 true),
        {"angle_bias", SettingType::Float, 10.0, 0.0, 60.0,
         "degrees added to the tangent angle: horizons below it do not occlude (hides "
         "tessellation and depth-precision self-occlusion)",
         false},
        gi::DepthAwareBlur::radiusSetting(2),
        {"interleave", SettingType::Bool, 1, 0, 1,
         "rotate the directions and jitter the steps in a 4x4 pixel pattern (per-pixel "
         "randomization) for the blur to average",
         false},
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    h_.radius = s.handle<double>("radius");
    h_.angle_bias = s.handle<double>("angle_bias");
    h_.interleave = s.handle<bool>("interleave");
    h_.directions = s.handle<int>("directions");
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "hbao");
    using gi::hbao::Uniforms;
    // Graph-changing settings are specialization constants: the loops unroll.
    gi::vk::ComputeDesc desc{"hbao: hbao.comp",
                             {std::begin(hbao_comp), std::end(hbao_comp)},
                             {uint32_t(s.integer("directions")), uint32_t(s.integer("steps"))}};
    desc.blocks.uniforms = {
        {"hbao", gi::vk::cppBlock<Uniforms>(
                     "gi::hbao::Uniforms",
                     {GI_BLOCK_MEMBER(Uniforms, radius), GI_BLOCK_MEMBER(Uniforms, invRadius2),
                      GI_BLOCK_MEMBER(Uniforms, cosBias), GI_BLOCK_MEMBER(Uniforms, sinBias),
                      GI_BLOCK_MEMBER(Uniforms, noise)})}};
    hbao_ = gi::vk::Pipeline::compute(vk, desc);
    // The blur radius is compiled into the blur (changesGraph: prepare runs again).
    if (s.integer("blur_radius") > 0) blur_.prepare(ctx, s.integer("blur_radius"));
    uniforms_.create(vk);
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
                                        {"hbao", &hbao_, "outAO", kGroupX, kGroupY,
                                         [this, values = &settings](gi::vk::DescriptorWriter& w) {
                                           upload(*values);
                                           w.buffer("hbao", uniforms_.handle());
                                         }},
                                        blurRadius > 0 ? "hbao_raw" : res::kAO);
    if (blurRadius > 0)
      ao = blur_.addPass(graph, ctx, "hbao_blur", ao, res::kAO,
                         [values = &settings, radius = h_.radius] {
                           return float(gi::hbao::kBlurDepthTolerance * (*values)[radius]);
                         });
    graph.blackboard().put(res::kAO, ao);
  }

 private:
  void upload(const gi::SettingValues& s) {
    const std::array<double, 4> key = {s[h_.radius], s[h_.angle_bias], s[h_.interleave] ? 1.0 : 0.0,
                                       double(s[h_.directions])};
    uniforms_.update(
        key, [&] { return gi::hbao::makeUniforms(key[0], key[1], key[2] != 0.0, int(key[3])); });
  }

  gi::vk::Pipeline hbao_;
  gi::DepthAwareBlur blur_;
  struct Handles {  // typed settings, found by name once in prepare()
    gi::Setting<double> radius, angle_bias;
    gi::Setting<int> directions;
    gi::Setting<bool> interleave;
  } h_;
  gi::UniformBlock<gi::hbao::Uniforms> uniforms_;  // rewritten only when a setting changed
};

}  // namespace

GI_EFFECT_MODULE(HbaoEffect)
