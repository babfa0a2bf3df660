// Alchemy screen-space ambient obscurance (McGuire, Osman, Bukowski, Hennessy 2011; seed 003):
// the estimator of eq. 10 with spiral taps on the projected disk of the world radius r and 4x4
// interleaved rotations (alchemy.comp, alchemy_kernel.h), a separable cross-bilateral filter
// (alchemy_blur.glsl) and an optional guard band: the scene drawn again, through the engine's
// GPU scene service, into a G-buffer `guard_band` pixels larger on each side, so that taps
// leaving the screen still find occluders. Publishes "ao" (lighting multiplies the environment
// term by it).
#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "alchemy.comp.h"         // const uint32_t alchemy_comp[]
#include "alchemy_blur_x.comp.h"  // const uint32_t alchemy_blur_x_comp[]
#include "alchemy_blur_y.comp.h"  // const uint32_t alchemy_blur_y_comp[]
#include "alchemy_kernel.h"
#include "gi/effect_registry.h"
#include "gi/effect_shader.h"
#include "gi/screen_space_ao.h"
#include "gi/separable_dispatch.h"
#include "gi/setting_uniforms.h"

namespace {

namespace res = gi::resources;
using gi::SettingType;

// The estimator's packed output (AO, 1/z, plane slopes) and the x-filtered copy: RGBA32F, so
// the filter reads one texel per tap. The final "ao" after the filter is R16F.
constexpr VkFormat kPackedFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kAOFormat = VK_FORMAT_R16_SFLOAT;
// Workgroup size of the shaders (local_size_x/y there): 32x16 measured fastest on llvmpipe.
constexpr uint32_t kGroupX = 32, kGroupY = 16;

class AlchemyEffect : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    return gi::aoEffectInfo(
        "alchemy",
        "Alchemy screen-space ambient obscurance (McGuire et al. 2011: eq. 10, spiral taps, "
        "cross-bilateral filter, guard band)");
  }

  // The Alchemy integral of eq. 10 (README "What it estimates"): sigma = intensity, u = 0,
  // epsilon, k = contrast, within r; the bias beta is a depth-precision concession, not part
  // of the quantity. The estimator does not converge to it: its taps are uniform on a screen
  // disk, not in direction, so it estimates a view-dependent disk integral (README "What the
  // estimator's expectation really is"; test_alchemy's AlchemyExpectation measures the gap).
  gi::EstimatedQuantity estimatedQuantity(const gi::SettingValues& s) const override {
    gi::EstimatedQuantity q;
    // What eq. 10's sum converges to: the screen-disk integral (README "What the estimator's
    // expectation really is"), not the hemisphere integral of eq. 8-9 (Kind::Alchemy).
    q.kind = gi::EstimatedQuantity::Kind::AlchemyDisk;
    q.radius = s.number("radius");
    q.sigma = s.number("intensity");
    q.u = 0.0;
    q.epsilon = gi::alchemy::absoluteEpsilon(s.number("epsilon"), q.radius);
    q.contrast = s.number("contrast");
    q.bias = s.number("bias");
    return q;
  }

  std::vector<gi::SettingDesc> settings() const override {
    using gi::alchemy::kMaxBlurRadius, gi::alchemy::kMaxGuardBand, gi::alchemy::kMaxSamples;
    gi::SettingDesc epsilon{"epsilon",
                            SettingType::Float,
                            gi::alchemy::kDefaultRelativeEpsilon,
                            1e-8,
                            4.0,
                            "epsilon relative to r^2: the denominator is v.v + epsilon r^2 (so "
                            "it follows a scaled scene); larger values lighten corners (light "
                            "leaks)",
                            false};
    epsilon.logScale = true;
    return {
        gi::aoRadiusSetting("world-space radius r: taps lie on its projected disk, occluders "
                            "farther than r count nothing"),
        gi::SettingDesc::samples("samples", 12, 1, kMaxSamples,
                                 "taps s per pixel (specialized: a change rebuilds the pipeline)",
                                 true),
        {"bias", SettingType::Float, 1e-4, 0.0, 0.1,
         "bias beta: the numerator is max(0, v.n - beta z), z the view distance (the paper's "
         "z_C beta); removes self-occlusion from depth precision",
         false},
        gi::SettingDesc::length("intensity", 1.0, 0.0, 1e9,
                                "intensity sigma, a world length (like u in eq. 8; a model "
                                "loaded without a scene file scales it with r): A = max(0, 1 - "
                                "(2 sigma / s) sum)^k; higher is darker"),
        {"contrast", SettingType::Float, 1.0, 0.1, 8.0,
         "contrast k, the exponent of eq. 10: higher darkens the occluded parts more", false},
        epsilon,
        {"blur_radius", SettingType::Int, 4, 0, kMaxBlurRadius,
         "cross-bilateral filter radius in pixels, two separable passes of 2 radius + 1 taps (0: "
         "no filter; even radii cancel the 4x4 interleave pattern exactly)",
         true},
        {"guard_band", SettingType::Int, 0, 0, kMaxGuardBand,
         "pixels drawn beyond each screen edge (the scene is drawn again into a larger G-buffer) "
         "so that taps leaving the screen find occluders; 0: off, off-screen taps are unoccluded",
         true},
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "alchemy");
    using gi::alchemy::Uniforms;
    const int samples = s.integer("samples"), band = s.integer("guard_band"),
              blur = s.integer("blur_radius");
    const gi::vk::BlockChecks params{
        {},
        {{"params", GI_CPP_BLOCK(Uniforms, radius, bias, scale, contrast, epsilon, blurTolerance,
                                 radius2, pad, taps)}}};
    ao_ = gi::vk::Pipeline::compute(vk,
                                    gi::computeShader("alchemy: alchemy.comp", alchemy_comp,
                                                      {uint32_t(samples), uint32_t(band)}, params));
    if (blur > 0) {
      blurX_ = gi::vk::Pipeline::compute(
          vk, gi::computeShader("alchemy: alchemy_blur_x.comp", alchemy_blur_x_comp,
                                {uint32_t(blur)}, params));
      blurY_ = gi::vk::Pipeline::compute(
          vk, gi::computeShader("alchemy: alchemy_blur_y.comp", alchemy_blur_y_comp,
                                {uint32_t(blur)}, params));
    }
    uniforms_.prepare(vk, s, {"radius", "bias", "intensity", "contrast", "epsilon", "samples"},
                      [](const auto& k) {
                        return gi::alchemy::makeUniforms(k[0], k[1], k[2], k[3],
                                                         gi::alchemy::absoluteEpsilon(k[4], k[0]),
                                                         int(k[5]));
                      });
    if (band > 0 && !view_) view_ = ctx.createView();
  }

  // The guard-band view: the main camera with its projection widened so that the band image's
  // inner region is the main image pixel for pixel. NDC scale by W / (W + 2 band) (and H / (H +
  // 2 band)) maps pixel x of the main view to pixel x + band of the larger one.
  void update(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    const int band = s.integer("guard_band");
    if (band <= 0 || !view_) return;
    const VkExtent2D e = ctx.outputExtent();
    const VkExtent2D big{e.width + 2 * uint32_t(band), e.height + 2 * uint32_t(band)};
    gi::CameraView camera = ctx.camera();
    const float sx = float(e.width) / float(big.width), sy = float(e.height) / float(big.height);
    for (int c = 0; c < 4; ++c) {  // rows 0 and 1 of the (column-major) projection
      camera.proj[c][0] *= sx;
      camera.proj[c][1] *= sy;
    }
    view_->setCamera(camera, big);
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle depth, packed, raw, half, ao;
      std::vector<gi::TextureHandle> gbuffer;  // guard band: the larger G-buffer's colours
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    const int blurRadius = settings.integer("blur_radius");  // changesGraph: fixed per graph
    const int band = settings.integer("guard_band");         // changesGraph
    const VkSampler nearest = ctx.nearestSampler();
    VkBuffer frame = ctx.frameUniforms();

    if (band > 0) {
      // The scene again, into a G-buffer 2 band pixels larger, through the widened view.
      const VkExtent2D e = ctx.outputExtent();
      const uint32_t w = e.width + 2 * uint32_t(band), h = e.height + 2 * uint32_t(band);
      gi::GpuScene& scene = ctx.scene();
      frame = view_->buffer();
      graph.addPass(
          "alchemy_guard_band",
          [&](gi::PassBuilder& b) {
            scene.declareRead(b);
            auto target = [&](const std::string& name, VkFormat f, gi::TextureUsage u) {
              return b.write(
                  b.create(name, gi::TextureDesc{f, gi::SizeClass::Absolute, 1.0f, w, h}), u);
            };
            io->depth = target("alchemy_band_depth", gi::kSceneDepthFormat,
                               gi::TextureUsage::DepthAttachment);
            const auto formats = gi::sceneColorFormats(gi::SceneOutputs::GBuffer);
            for (size_t i = 0; i < formats.size(); ++i)
              io->gbuffer.push_back(target("alchemy_band_g" + std::to_string(i), formats[i],
                                           gi::TextureUsage::ColorAttachment));
            io->packed = io->gbuffer[0];  // the packed G-buffer comes first in sceneColorFormats
          },
          [io, &scene, view = frame](gi::PassContext& pc) {
            gi::SceneTargets t{pc.view(io->depth), {}, pc.extent(io->depth)};
            for (gi::TextureHandle g : io->gbuffer) t.colors.push_back(pc.view(g));
            scene.drawGBuffer(pc, t, view);
          });
    }

    // The renderer keeps `settings` alive for the graph's life and updates it in place, so
    // uniform-only settings are read (and uploaded) when the pass is recorded, every frame.
    graph.addPass(
        "alchemy",
        [&](gi::PassBuilder& b) {
          io->depth = b.read(band > 0 ? io->depth : bb.texture(res::kDepth));
          io->packed = b.read(band > 0 ? io->packed : bb.texture(res::kGBuffer));
          io->raw = b.write(
              b.create(blurRadius > 0 ? "alchemy_raw" : res::kAO, gi::TextureDesc{kPackedFormat}),
              gi::TextureUsage::StorageWrite);
        },
        [this, io, values = &settings, frame, nearest](gi::PassContext& pc) {
          // The epsilon setting is relative to r^2: the block holds the absolute one.
          const VkBuffer params = uniforms_.upload(*values);
          gi::vk::DescriptorWriter w(ao_);
          w.buffer("Frame", frame)
              .buffer("params", params)
              .texture("gDepth", pc.view(io->depth), nearest)
              .texture("giGBuffer", pc.view(io->packed), nearest)
              .image("outAO", pc.view(io->raw));
          const VkExtent2D e = pc.extent(io->raw);
          pc.dispatch(ao_, w, e, kGroupX, kGroupY);
        });

    io->ao = io->raw;
    if (blurRadius > 0) {
      // Separable: along x into `half`, then along y into "ao", two dispatches in one pass.
      graph.addPass(
          "alchemy_blur",
          [&](gi::PassBuilder& b) {
            io->raw = b.read(io->raw);
            io->half = b.write(b.create("alchemy_blur_x", gi::TextureDesc{kPackedFormat}),
                               gi::TextureUsage::StorageWrite);
            io->ao = b.write(b.create(res::kAO, gi::TextureDesc{kAOFormat}),
                             gi::TextureUsage::StorageWrite);
          },
          [this, io, nearest](gi::PassContext& pc) {
            gi::dispatchSeparable(
                pc,
                {.x = &blurX_,
                 .y = &blurY_,
                 .input = "inAO",
                 .output = "outAO",
                 .sampler = nearest,
                 .bind = [this](
                             gi::vk::DescriptorWriter& w,
                             const gi::vk::Pipeline&) { w.buffer("params", uniforms_.handle()); },
                 .groupX = kGroupX,
                 .groupY = kGroupY},
                io->raw, io->half, io->ao);
          });
    }
    bb.put(res::kAO, io->ao);
  }

 private:
  gi::vk::Pipeline ao_, blurX_, blurY_;
  // Rewritten only when a setting changed.
  gi::SettingUniforms<gi::alchemy::Uniforms, 6> uniforms_;
  std::shared_ptr<gi::ViewUniforms> view_;  // the guard-band view (guard_band > 0)
};

}  // namespace

GI_EFFECT_MODULE(AlchemyEffect)
