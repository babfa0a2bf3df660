// Ground-truth ambient occlusion (Jimenez et al. 2016; RTR 4th ed. 11.3.7): horizon search in
// slices through the view vector, the cosine-weighted visible arc in closed form, optional bent
// normals and multi-bounce fit, and a depth-aware blur that removes the 4x4 interleave pattern
// (optionally all at a reduced resolution, upsampled by the engine's blur). Publishes "ao" (and
// "gtao_bent_normal"). Estimator: gtao_params.h; settings: README.md.
#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "gi/depth_aware_blur.h"
#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/uniform_block.h"
#include "gi/vk/pipeline.h"
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
constexpr uint32_t kGroupX = 32, kGroupY = 16;  // local_size of both shaders (32x16: llvmpipe)

class GtaoEffect : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    gi::EffectInfo i;
    i.name = "gtao";
    i.version = "1.0";
    i.description =
        "ground-truth ambient occlusion (horizon slices, cosine-weighted; optional bent normals "
        "and multi-bounce)";
    i.stage = gi::EffectStage::BeforeLighting;
    i.reads = {res::kDepth, res::kGBuffer, res::kNormal};  // normal: the bent normal when off
    i.writes = {res::kAO, kBentNormal};
    i.debugView = res::kAO;
    // Declares cosine-weighted AO of `radius` (the default estimatedQuantity): with falloff
    // 0, thickness 0 and multi_bounce off it is the reference's quantity; those settings
    // depart from it.
    i.estimates = gi::GroundTruth::AmbientOcclusion;
    return i;
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::SettingDesc::length("radius", 0.5, 1e-6, 1e9,
                                "world-space radius R: occluders farther than R are ignored"),
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
        {"interleave", SettingType::Bool, 1, 0, 1,
         "rotate the slices and jitter the steps in a 4x4 pixel pattern for the blur to average",
         false},
        {"downsample", SettingType::Int, 1, 1, gi::DepthAwareBlur::kMaxScale,
         "compute at 1 / downsample of the resolution in each axis, blur there and upsample "
         "depth-aware to full resolution (1: full resolution)",
         true},
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    h_.radius = s.handle<double>("radius");
    h_.falloff = s.handle<double>("falloff");
    h_.thickness = s.handle<double>("thickness");
    h_.interleave = s.handle<bool>("interleave");
    h_.slices = s.handle<int>("slices");
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "gtao");
    using gi::gtao::Uniforms;
    // Graph-changing settings are specialization constants: the loops unroll and the optional
    // outputs vanish from the code when off.
    gi::vk::ComputeDesc desc{"gtao: gtao.comp",
                             {std::begin(gtao_comp), std::end(gtao_comp)},
                             {uint32_t(s.integer("slices")), uint32_t(s.integer("steps")),
                              s.flag("bent_normals") ? 1u : 0u, s.flag("multi_bounce") ? 1u : 0u,
                              uint32_t(s.integer("downsample"))}};
    desc.blocks.uniforms = {
        {"gtao", gi::vk::cppBlock<Uniforms>(
                     "gi::gtao::Uniforms",
                     {GI_BLOCK_MEMBER(Uniforms, radius), GI_BLOCK_MEMBER(Uniforms, falloffSlope),
                      GI_BLOCK_MEMBER(Uniforms, thickness), GI_BLOCK_MEMBER(Uniforms, pad),
                      GI_BLOCK_MEMBER(Uniforms, noise)})}};
    gtao_ = gi::vk::Pipeline::compute(vk, desc);
    // The blur radius and the downsampling are compiled into the blur (changesGraph: prepare
    // runs again); at a reduced resolution the blur also upsamples, even with radius 0.
    if (s.integer("blur_radius") > 0 || s.integer("downsample") > 1)
      blur_.prepare(ctx, s.integer("blur_radius"), s.integer("downsample"));
    uniforms_.create(vk);
    if (!unusedBent_) {
      gi::vk::ImageDesc d;
      d.format = kBentFormat;
      d.usage = VK_IMAGE_USAGE_STORAGE_BIT;
      unusedBent_ = gi::vk::Image(vk, d);
    }
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle depth, gbuffer, raw, ao, bent;
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    // changesGraph settings: fixed for this graph.
    const int blurRadius = settings.integer("blur_radius"),
              downsample = settings.integer("downsample");
    const bool blurred = blurRadius > 0 || downsample > 1;
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
          io->raw = b.write(
              b.create(blurred ? "gtao_raw" : res::kAO,
                       gi::TextureDesc{gi::DepthAwareBlur::kPackedFormat,
                                       gi::SizeClass::OutputRelative, 1.0f / float(downsample)}),
              gi::TextureUsage::StorageWrite);
          if (bentNormals) io->bent = b.write(bentTexture, gi::TextureUsage::StorageWrite);
        },
        [this, io, values = &settings, frame, nearest, bentNormals](gi::PassContext& pc) {
          upload(*values);
          if (!bentNormals) prepareUnusedBent(pc.cmd());
          gi::vk::DescriptorWriter w(gtao_);
          w.buffer("Frame", frame)
              .buffer("gtao", uniforms_.handle())
              .texture("gDepth", pc.view(io->depth), nearest)
              .texture("giGBuffer", pc.view(io->gbuffer), nearest)
              .image("outAO", pc.view(io->raw))
              .image("outBent", bentNormals ? pc.view(io->bent) : unusedBent_.view());
          const VkExtent2D e = pc.extent(io->raw);
          pc.dispatch(gtao_, w, e, kGroupX, kGroupY);
        });

    io->ao = io->raw;
    if (blurred)
      io->ao = blur_.addPass(graph, ctx, "gtao_blur", io->raw, res::kAO,
                             [values = &settings, radius = h_.radius] {
                               return float(gi::gtao::kBlurDepthTolerance * (*values)[radius]);
                             });
    bb.put(res::kAO, io->ao);
    bb.put(kBentNormal, bentNormals ? io->bent : bb.texture(res::kNormal));
  }

 private:
  void upload(const gi::SettingValues& s) {
    const std::array<double, 5> key = {s[h_.radius], s[h_.falloff], s[h_.thickness],
                                       s[h_.interleave] ? 1.0 : 0.0, double(s[h_.slices])};
    uniforms_.update(key, [&] {
      return gi::gtao::makeUniforms(key[0], key[1], key[2], key[3] != 0.0, int(key[4]));
    });
  }

  // Bent normals off: the shader never stores to binding 6 (specialized away), but the binding
  // must hold an image of the declared format. A 1x1 image of the effect's own, outside the
  // frame graph (a never-read graph transient may share memory with later ones), moved to
  // GENERAL once.
  void prepareUnusedBent(VkCommandBuffer cmd) {
    if (unusedBentReady_) return;
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = VK_PIPELINE_STAGE_2_NONE;
    b.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    b.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = unusedBent_.handle();
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
    unusedBentReady_ = true;
  }

  gi::vk::Pipeline gtao_;
  gi::DepthAwareBlur blur_;
  struct Handles {  // typed settings, found by name once in prepare()
    gi::Setting<double> radius, falloff, thickness;
    gi::Setting<int> slices;
    gi::Setting<bool> interleave;
  } h_;
  gi::UniformBlock<gi::gtao::Uniforms> uniforms_;  // rewritten only when a setting changed
  gi::vk::Image unusedBent_;
  bool unusedBentReady_ = false;
};

}  // namespace

GI_EFFECT_MODULE(GtaoEffect)
