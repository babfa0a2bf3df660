// Horizon-based ambient occlusion (Bavoil, Sainz and Dimitrov 2008): horizon search along
// screen directions with per-sample attenuation and an angle bias, 4x4 interleaved direction
// rotations and step jitter, and a depth-aware blur that removes the pattern. Publishes "ao".
// Estimator: hbao_params.h; settings: README.md.
#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "hbao.comp.h"       // const uint32_t hbao_comp[]
#include "hbao_blur.comp.h"  // const uint32_t hbao_blur_comp[]
#include "hbao_params.h"

namespace {

namespace res = gi::resources;
using gi::SettingType;

constexpr VkFormat kAOFormat = VK_FORMAT_R16_SFLOAT;
constexpr uint32_t kGroupX = 32, kGroupY = 16;  // local_size of both shaders (32x16: llvmpipe)

uint32_t groupsOf(uint32_t n, uint32_t size) {
  return (n + size - 1) / size;
}

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
    i.reads = {res::kDepth, res::kNormal};
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
        {"directions", SettingType::Int, 6, 1, gi::hbao::kMaxDirections,
         "screen directions per pixel (rotated per pixel by the 4x4 interleave)", true},
        {"steps", SettingType::Int, 4, 1, gi::hbao::kMaxSteps, "depth samples per direction", true},
        {"angle_bias", SettingType::Float, 10.0, 0.0, 60.0,
         "degrees added to the tangent angle: horizons below it do not occlude (hides "
         "tessellation and depth-precision self-occlusion)",
         false},
        {"blur_radius", SettingType::Int, 2, 0, gi::hbao::kMaxBlurRadius,
         "depth-aware blur radius in pixels (0: no blur pass; even radii cancel the 4x4 "
         "interleave pattern exactly)",
         true},
        {"interleave", SettingType::Bool, 1, 0, 1,
         "rotate the directions and jitter the steps in a 4x4 pixel pattern (per-pixel "
         "randomization) for the blur to average",
         false},
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "hbao");
    const auto ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
               tex = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
               img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    // Graph-changing settings are specialization constants: the loops unroll.
    hbao_ = gi::vk::Pipeline::compute(
        vk, {std::begin(hbao_comp), std::end(hbao_comp)},
        {{0, ubo}, {1, ubo}, {2, tex}, {3, tex}, {4, img}}, 0,
        {uint32_t(s.integer("directions")), uint32_t(s.integer("steps"))});
    const int blurRadius = std::max(1, s.integer("blur_radius"));
    blur_ = gi::vk::Pipeline::compute(vk, {std::begin(hbao_blur_comp), std::end(hbao_blur_comp)},
                                      {{0, ubo}, {1, tex}, {2, tex}, {3, tex}, {4, img}},
                                      sizeof(BlurPush), {uint32_t(blurRadius)});
    if (!uniforms_)
      uniforms_ =
          gi::vk::Buffer(vk, sizeof(gi::hbao::Uniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle depth, normal, raw, half, ao;
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    // changesGraph settings: fixed for this graph.
    const int blurRadius = settings.integer("blur_radius");
    const VkBuffer frame = ctx.frameUniforms();
    const VkSampler nearest = ctx.nearestSampler();

    graph.addPass(
        "hbao",
        [&](gi::PassBuilder& b) {
          io->depth = b.read(bb.texture(res::kDepth));
          io->normal = b.read(bb.texture(res::kNormal));
          io->raw =
              b.write(b.create(blurRadius > 0 ? "hbao_raw" : res::kAO, gi::TextureDesc{kAOFormat}),
                      gi::TextureUsage::StorageWrite);
        },
        [this, io, values = &settings, frame, nearest](gi::PassContext& pc) {
          upload(*values);
          gi::vk::DescriptorWriter w;
          w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frame)
              .buffer(1, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, uniforms_.handle())
              .sampled(2, pc.view(io->depth), nearest)
              .sampled(3, pc.view(io->normal), nearest)
              .storageImage(4, pc.view(io->raw));
          const VkExtent2D e = pc.extent(io->raw);
          dispatch(pc, hbao_, w, groupsOf(e.width, kGroupX), groupsOf(e.height, kGroupY));
        });

    io->ao = io->raw;
    if (blurRadius > 0) {
      // Separable: along x into `half`, then along y into "ao", two dispatches in one pass.
      graph.addPass(
          "hbao_blur",
          [&](gi::PassBuilder& b) {
            io->depth = b.read(io->depth);
            io->normal = b.read(io->normal);
            io->raw = b.read(io->raw);
            io->half = b.write(b.create("hbao_blur_x", gi::TextureDesc{kAOFormat}),
                               gi::TextureUsage::StorageWrite);
            io->ao = b.write(b.create(res::kAO, gi::TextureDesc{kAOFormat}),
                             gi::TextureUsage::StorageWrite);
          },
          [this, io, values = &settings, frame, nearest](gi::PassContext& pc) {
            const VkExtent2D e = pc.extent(io->ao);
            const float tolerance = float(gi::hbao::kBlurDepthTolerance * values->number("radius"));
            auto axis = [&](VkImageView in, VkImageLayout inLayout, VkImageView out, int dx) {
              gi::vk::DescriptorWriter w;
              w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, frame)
                  .sampled(1, pc.view(io->depth), nearest)
                  .sampled(2, pc.view(io->normal), nearest)
                  .sampled(3, in, nearest, inLayout)
                  .storageImage(4, out);
              const BlurPush push{{dx, 1 - dx}, tolerance};
              dispatch(pc, blur_, w, groupsOf(e.width, kGroupX), groupsOf(e.height, kGroupY), &push,
                       sizeof push);
            };
            axis(pc.view(io->raw), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, pc.view(io->half), 1);
            // The graph orders passes, not dispatches inside one: the y dispatch reads what the
            // x dispatch wrote (the image stays GENERAL, as storage images are).
            imageBarrier(pc.cmd(), pc.image(io->half));
            axis(pc.view(io->half), VK_IMAGE_LAYOUT_GENERAL, pc.view(io->ao), 0);
          });
    }
    bb.put(res::kAO, io->ao);
  }

 private:
  struct BlurPush {
    int32_t axis[2];
    float tolerance;
  };

  // Host-visible and written while recording: the renderer waits for each frame before it
  // records the next, so the GPU is not reading it. Rewritten only when a setting changed.
  void upload(const gi::SettingValues& s) {
    const std::array<double, 4> key = {s.number("radius"), s.number("angle_bias"),
                                       s.flag("interleave") ? 1.0 : 0.0,
                                       double(s.integer("directions"))};
    if (key == uploaded_) return;
    const gi::hbao::Uniforms u = gi::hbao::makeUniforms(key[0], key[1], key[2] != 0.0, int(key[3]));
    uniforms_.write(&u, sizeof u);
    uploaded_ = key;
  }

  static void dispatch(gi::PassContext& pc, const gi::vk::Pipeline& p, gi::vk::DescriptorWriter& w,
                       uint32_t x, uint32_t y, const void* push = nullptr, uint32_t pushBytes = 0) {
    pc.descriptors().bind(pc.cmd(), p, w);
    if (pushBytes > 0)
      vkCmdPushConstants(pc.cmd(), p.layout(), VK_SHADER_STAGE_ALL, 0, pushBytes, push);
    vkCmdDispatch(pc.cmd(), x, y, 1);
  }

  // Compute write -> compute sampled read of a storage image that stays in GENERAL.
  static void imageBarrier(VkCommandBuffer cmd, VkImage image) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = b.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    b.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
    b.oldLayout = b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
  }

  gi::vk::Pipeline hbao_, blur_;
  gi::vk::Buffer uniforms_;
  std::optional<std::array<double, 4>> uploaded_;  // the settings uniforms_ holds
};

}  // namespace

GI_EFFECT_MODULE(HbaoEffect)
