// Screen-space ambient occlusion (RTR 11.3.6; seed 001 §4.2-4.3): normal-oriented hemisphere
// taps tested against the depth buffer with a range check, 4x4 interleaved kernel rotations,
// and a depth-aware blur that removes the interleave pattern. Publishes "ao", which the
// lighting pass applies to the environment term. Estimator and kernel: ssao_kernel.h.
#include <vector>

#include "gi/effect_registry.h"
#include "gi/effect_shader.h"
#include "gi/screen_space_ao.h"
#include "ssao.comp.h"  // const uint32_t ssao_comp[]
#include "ssao_kernel.h"

namespace {

using gi::SettingType;
using gi::ssao::Uniforms;

class SsaoEffect : public gi::ScreenSpaceAOEffect<Uniforms, 5> {
 public:
  gi::EffectInfo info() const override {
    return gi::aoEffectInfo(
        "ssao",
        "screen-space ambient occlusion (hemisphere taps, 4x4 interleave, depth-aware blur)");
  }

  // Obscurance with the linear membership mu(d) = d / R (ssao_kernel.h: cosine-distributed
  // directions with distances uniform in [0, R] count a hit at d as occluding 1 - d / R of the
  // taps). Exact for intensity 1 (the default): AO = 1 - intensity x occluded fraction.
  gi::EstimatedQuantity estimatedQuantity(const gi::SettingValues& s) const override {
    return {.kind = gi::EstimatedQuantity::Kind::Obscurance,
            .radius = s.number("radius"),
            .membership = "linear"};
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::aoRadiusSetting("world-space radius R of the sampled hemisphere (a model loaded "
                            "without a scene file scales the default to its size)"),
        gi::SettingDesc::samples("samples", 16, 1, gi::ssao::kMaxSamples, "taps per pixel", false),
        {"bias", SettingType::Float, 0.025, 0.0, 0.5,
         "an occluder must be this far in front of a tap, as a fraction of the radius", false},
        {"intensity", SettingType::Float, 1.0, 0.0, 4.0,
         "AO = 1 - intensity x occluded fraction (clamped to [0, 1])", false},
        gi::DepthAwareBlur::radiusSetting(2),
        gi::interleaveSetting(
            "rotate the kernel in a 4x4 pixel pattern (16 rotations) for the blur to average"),
    };
  }

  // Uniform-only settings are read (and the kernel rebuilt when one changed) as the pass
  // records, every frame.
  void prepare(gi::EffectContext& ctx, const gi::SettingValues& settings) override {
    prepareAO(ctx, settings, "ssao", gi::computeShader("ssao: ssao.comp", ssao_comp),
              gi::ssao::kBlurDepthTolerance,
              {"ssao",
               GI_CPP_BLOCK(Uniforms, params, counts, rotation, kernel),
               {"radius", "bias", "intensity", "samples", "interleave"},
               [](const auto& k) {
                 return gi::ssao::makeUniforms(k[0], k[1], k[2], int(k[3]), k[4] != 0.0);
               }});
  }
};

}  // namespace

GI_EFFECT_MODULE(SsaoEffect)
