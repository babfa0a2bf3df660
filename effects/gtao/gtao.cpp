// Ground-truth ambient occlusion (Jimenez et al. 2016; RTR 4th ed. 11.3.7): horizon search in
// slices through the view vector, the cosine-weighted visible arc in closed form, optional bent
// normals and multi-bounce fit, and a depth-aware blur that removes the 4x4 interleave pattern
// (optionally all at a reduced resolution, upsampled by the engine's blur). Publishes "ao" (and
// "gtao_bent_normal"). Estimator: gtao_params.h; settings: README.md.
#include <memory>
#include <vector>

#include "gi/effect_registry.h"
#include "gi/effect_shader.h"
#include "gi/screen_space_ao.h"
#include "gi/setting_uniforms.h"
#include "gi/vk/resources.h"
#include "gtao.comp.h"  // const uint32_t gtao_comp[]
#include "gtao_params.h"

namespace {

namespace res = gi::resources;
using gi::SettingType;

// View-space bent normal (xyz, w = 1 on geometry), the G-buffer normal's layout. When the
// setting is off, the G-buffer normal itself is published under this name (no pass, no
// texture): the engine requires every declared write to be published.
constexpr const char* kBentNormal = "gtao_bent_normal";
constexpr VkFormat kBentFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

class GtaoEffect : public gi::Effect {
 public:
  // Declares cosine-weighted AO of `radius` (the default estimatedQuantity): with falloff 0,
  // thickness 0 and multi_bounce off it is the reference's quantity; those settings depart from
  // it.
  gi::EffectInfo info() const override {
    gi::EffectInfo i = gi::aoEffectInfo(
        "gtao",
        "ground-truth ambient occlusion (horizon slices, cosine-weighted; optional bent normals "
        "and multi-bounce)");
    i.reads.push_back(res::kNormal);  // the bent normal when off
    i.writes.push_back(kBentNormal);
    return i;
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::aoRadiusSetting("world-space radius R: occluders farther than R are ignored"),
        gi::SettingDesc::samples("slices", 3, 1, gi::gtao::kMaxSlices,
                                 "slice planes through the view vector per pixel (XeGTAO low 1, "
                                 "medium 2, high 3, ultra 9)",
                                 true),
        gi::SettingDesc::samples(
            "steps", 3, 1, gi::gtao::kMaxSteps,
            "depth samples per side of each slice (XeGTAO low 2, medium 2, high 3, ultra 3)", true),
        {"falloff", SettingType::Float, 0.0, 0.0, 1.0,
         "fraction of R over which an occluder's weight fades to 0 before R (0: the reference's "
         "hard cut-off)",
         false},
        {"thickness", SettingType::Float, 0.0, 0.0, 1.0,
         "thickness heuristic: a sample below the horizon pulls it down by this blend (0: off, "
         "occluders are infinitely thick)",
         false},
        {"bent_normals", SettingType::Bool, 0, 0, 1,
         "also write the view-space bent normal to 'gtao_bent_normal' (off: that name is the "
         "G-buffer normal, at no cost)",
         true},
        {"multi_bounce", SettingType::Bool, 0, 0, 1,
         "Jimenez et al. multi-bounce fit: AO' = max(AO, ((a AO + b) AO + c) AO) from the albedo "
         "(reads the albedo G-buffer)",
         true},
        gi::DepthAwareBlur::radiusSetting(2),
        gi::interleaveSetting("rotate the slices and jitter the steps in a 4x4 pixel pattern for "
                              "the blur to average"),
        {"downsample", SettingType::Int, 1, 1, gi::DepthAwareBlur::kMaxScale,
         "compute at 1 / downsample of the resolution in each axis, blur there and upsample "
         "depth-aware to full resolution (1: full resolution)",
         true},
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    using gi::gtao::Uniforms;
    // Graph-changing settings are specialization constants: the loops unroll and the optional
    // outputs vanish from the code when off.
    gi::vk::ComputeDesc desc =
        gi::computeShader("gtao: gtao.comp", gtao_comp,
                          {uint32_t(s.integer("slices")), uint32_t(s.integer("steps")),
                           s.flag("bent_normals") ? 1u : 0u, s.flag("multi_bounce") ? 1u : 0u,
                           uint32_t(s.integer("downsample"))});
    desc.blocks.uniforms = {
        {"gtao", GI_CPP_BLOCK(Uniforms, radius, falloffSlope, thickness, pad, noise)}};
    // At a reduced resolution the blur also upsamples, even with radius 0.
    ao_.prepare(ctx, s, "gtao", desc, gi::gtao::kBlurDepthTolerance, s.integer("downsample"));
    uniforms_.prepare(ctx.vulkan(), s, {"radius", "falloff", "thickness", "interleave", "slices"},
                      [](const auto& k) {
                        return gi::gtao::makeUniforms(k[0], k[1], k[2], k[3] != 0.0, int(k[4]));
                      });
    if (!unusedBent_) {
      gi::vk::ImageDesc d;
      d.format = kBentFormat;
      d.usage = VK_IMAGE_USAGE_STORAGE_BIT;
      unusedBent_ = gi::vk::Image(ctx.vulkan(), d);
    }
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle depth, gbuffer, raw, bent;
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    // changesGraph settings: fixed for this graph.
    const int downsample = settings.integer("downsample");
    const bool bentNormals = settings.flag("bent_normals");
    const VkBuffer frame = ctx.frameUniforms();
    const VkSampler nearest = ctx.nearestSampler();
    // Persistent, not transient: no pass of the graph may read the bent normal, and the graph
    // aliases a transient whose last use is the pass that wrote it with later transients (its
    // aliasing barrier then reports a write-after-write hazard); a persistent texture is never
    // aliased and stays readable after the frame.
    const gi::TextureHandle bentTexture =
        bentNormals ? graph.persistentTexture(kBentNormal, gi::TextureDesc{kBentFormat})
                    : gi::TextureHandle{};

    graph.addPass(
        "gtao",
        [&](gi::PassBuilder& b) {
          io->depth = b.read(bb.texture(res::kDepth));
          io->gbuffer = b.read(bb.texture(res::kGBuffer));
          io->raw =
              b.write(b.create(ao_.rawName(), gi::TextureDesc{gi::DepthAwareBlur::kPackedFormat,
                                                              gi::SizeClass::OutputRelative,
                                                              1.0f / float(downsample)}),
                      gi::TextureUsage::StorageWrite);
          if (bentNormals) io->bent = b.write(bentTexture, gi::TextureUsage::StorageWrite);
        },
        [this, io, values = &settings, frame, nearest, bentNormals](gi::PassContext& pc) {
          if (!bentNormals) prepareUnusedBent(pc.cmd());
          const VkBuffer params = uniforms_.upload(*values);
          const gi::vk::Pipeline& gtao = ao_.pipeline();
          gi::vk::DescriptorWriter w(gtao);
          w.buffer("Frame", frame)
              .buffer("gtao", params)
              .texture("gDepth", pc.view(io->depth), nearest)
              .texture("giGBuffer", pc.view(io->gbuffer), nearest)
              .image("outAO", pc.view(io->raw))
              .image("outBent", bentNormals ? pc.view(io->bent) : unusedBent_.view());
          const VkExtent2D e = pc.extent(io->raw);
          pc.dispatch(gtao, w, e, gi::ScreenSpaceAO::kGroupX, gi::ScreenSpaceAO::kGroupY);
        });

    ao_.publish(graph, ctx, io->raw, settings);
    bb.put(kBentNormal, bentNormals ? io->bent : bb.texture(res::kNormal));
  }

 private:
  // Bent normals off: the shader never stores to binding 6 (specialized away), but the binding
  // must hold an image of the declared format. A 1x1 image of the effect's own, outside the
  // frame graph (a never-read graph transient may share memory with later ones), moved to
  // GENERAL once.
  void prepareUnusedBent(VkCommandBuffer cmd) {
    if (unusedBentReady_) return;
    gi::vk::imageBarrier(cmd, unusedBent_.handle(), VK_IMAGE_ASPECT_COLOR_BIT,
                         VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                         VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                         VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    unusedBentReady_ = true;
  }

  gi::ScreenSpaceAO ao_;
  gi::SettingUniforms<gi::gtao::Uniforms, 5> uniforms_;
  gi::vk::Image unusedBent_;
  bool unusedBentReady_ = false;
};

}  // namespace

GI_EFFECT_MODULE(GtaoEffect)
