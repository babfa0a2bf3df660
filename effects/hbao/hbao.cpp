// Horizon-based ambient occlusion (Bavoil, Sainz and Dimitrov 2008): horizon search along
// screen directions with per-sample attenuation and an angle bias, 4x4 interleaved direction
// rotations and step jitter, and a depth-aware blur that removes the pattern. Publishes "ao".
// Estimator: hbao_params.h; settings: README.md.
#include <vector>

#include "gi/effect_registry.h"
#include "gi/effect_shader.h"
#include "gi/screen_space_ao.h"
#include "hbao.comp.h"  // const uint32_t hbao_comp[]
#include "hbao_params.h"

namespace {

using gi::hbao::Uniforms;

class HbaoEffect : public gi::ScreenSpaceAOEffect<Uniforms, 4> {
 public:
  // Declares AO of `radius` (the default estimatedQuantity): its own quantity (README: no
  // cosine term, elevations from the image plane, attenuation W(r) = 1 - r^2 / R^2 instead
  // of a hard cut at R, the angle bias) has no reference, so both columns are against AO.
  gi::EffectInfo info() const override {
    return gi::aoEffectInfo(
        "hbao",
        "horizon-based ambient occlusion (Bavoil et al. 2008: attenuated horizons, angle bias, "
        "4x4 interleave, depth-aware blur)");
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::aoRadiusSetting("world-space radius R: samples farther than R are ignored, nearer "
                            "ones attenuated by 1 - r^2 / R^2"),
        gi::SettingDesc::samples(
            "directions", 6, 1, gi::hbao::kMaxDirections,
            "screen directions per pixel (rotated per pixel by the 4x4 interleave)", true),
        gi::SettingDesc::samples("steps", 4, 1, gi::hbao::kMaxSteps, "depth samples per direction",
                                 true),
        {"angle_bias", gi::SettingType::Float, 10.0, 0.0, 60.0,
         "degrees added to the tangent angle: horizons below it do not occlude (hides "
         "tessellation and depth-precision self-occlusion)",
         false},
        gi::DepthAwareBlur::radiusSetting(2),
        gi::interleaveSetting("rotate the directions and jitter the steps in a 4x4 pixel pattern "
                              "(per-pixel randomization) for the blur to average"),
    };
  }

  // Graph-changing settings are specialization constants (the loops unroll); uniform-only ones
  // are read (and the block rebuilt when one changed) as the pass records.
  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    prepareAO(
        ctx, s, "hbao",
        gi::computeShader("hbao: hbao.comp", hbao_comp,
                          {uint32_t(s.integer("directions")), uint32_t(s.integer("steps"))}),
        gi::hbao::kBlurDepthTolerance,
        {"hbao",
         GI_CPP_BLOCK(Uniforms, radius, invRadius2, cosBias, sinBias, noise),
         {"radius", "angle_bias", "interleave", "directions"},
         [](const auto& k) { return gi::hbao::makeUniforms(k[0], k[1], k[2] != 0.0, int(k[3])); }});
  }
};

}  // namespace

GI_EFFECT_MODULE(HbaoEffect)
