// "lighting": composes the lit image from the G-buffer, the lights and shadow maps, the
// environment and the optional inputs effects publish (ao, ambient, indirect, contact_shadow,
// direct_light; neutral when absent: one table, kLightingInputs in builtin_passes.h, gives
// each one's resource, fallback, and the names of its sampler and specialization constant in
// lighting.comp, whose reflection gives their numbers).
#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <string_view>

#include "gi/errors.h"
#include "gi/lit_surface.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/shader_interface.h"
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

namespace res = resources;

class LightingPass final : public Effect {
 public:
  explicit LightingPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"lighting", "2",
                 "direct light with shadows + environment x ambient visibility + indirect"};
    i.reads = {res::kDepth,         res::kGBuffer,     res::kLights,        res::kShadowViews,
               res::kShadowMaps,    res::kAO,          res::kAmbient,       res::kIndirect,
               res::kContactShadow, res::kDirectLight, res::kEnvironmentMap};
    i.writes = {res::kLit};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    ctx.vulkan().requireWorkgroup(kScreenGroupX, kScreenGroupY, "lighting");
    if (!spirv_.empty()) return;
    spirv_ = vk::loadSpirv("lighting.comp");
    constants_ = vk::reflectSpecializationConstants(spirv_, kShader);
    const vk::ShaderInterface shader =
        vk::reflectShader(spirv_, VK_SHADER_STAGE_COMPUTE_BIT, kShader);
    for (const LightingInput& in : kLightingInputs) {
      constant(in.constant);  // the shader must declare each input's constant ...
      if (!shader.find(in.texture))
        throw Error(ErrorKind::ShaderInterface, "",  // ... and its sampler
                    std::string(kShader) + " has no sampler '" + in.texture +
                        "' for the optional input '" + in.resource + "'");
    }
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    struct Io {
      LitSurfaceInputs surface;  // the G-buffer and the lights (gi/lit_surface.h)
      std::array<TextureHandle, kLightingInputs.size()> inputs;  // published or the neutral one
      std::array<bool, kLightingInputs.size()> fallback{};
      TextureHandle environment, lit;
    };
    auto io = std::make_shared<Io>();

    Blackboard& bb = graph.blackboard();
    graph.addPass(
        "lighting",
        [&](PassBuilder& b) {
          io->surface.read(b, bb);
          for (size_t i = 0; i < kLightingInputs.size(); ++i) {
            io->inputs[i] = b.readOptional(kLightingInputs[i].resource);
            io->fallback[i] = b.isFallback(io->inputs[i]);
          }
          // The contact factors multiply single lights' shadows; a published direct_light has
          // summed the lights already, so whoever publishes it must have applied them.
          if (!io->fallback[input(res::kContactShadow)] && !io->fallback[input(res::kDirectLight)])
            throw Error(ErrorKind::Usage, "",
                        "both 'contact_shadow' and 'direct_light' are published: the effect "
                        "that publishes direct_light must apply the contact shadows itself");
          io->environment = b.read(bb.texture(res::kEnvironmentMap));
          io->lit = b.write(b.create(res::kLit, TextureDesc{VK_FORMAT_R16G16B16A16_SFLOAT}),
                            TextureUsage::StorageWrite);
        },
        [this, io, frame = ctx.frameUniforms()](PassContext& pc) {
          const VkSampler nearest = s_.nearest, linear = s_.linear;
          const VkExtent2D e = pc.extent(io->lit);
          // An optional input is read once per pixel at the output's size, bilinearly otherwise.
          std::array<uint32_t, kLightingInputs.size()> modes{};
          for (size_t i = 0; i < modes.size(); ++i) {
            const VkExtent2D in = pc.extent(io->inputs[i]);
            modes[i] = io->fallback[i]                                ? 0u
                       : in.width == e.width && in.height == e.height ? 1u
                                                                      : 2u;
          }
          const vk::Pipeline& pipeline = variant(modes);
          vk::DescriptorWriter w(pipeline);
          w.buffer("Frame", frame);
          io->surface.bind(w, pc, nearest);
          w.image("outLit", pc.view(io->lit))
              .texture("environmentMap", pc.view(io->environment), s_.scene.linearRepeat());
          for (size_t i = 0; i < kLightingInputs.size(); ++i)
            w.texture(kLightingInputs[i].texture, pc.view(io->inputs[i]), linear);
          pc.dispatch(pipeline, w, e, kScreenGroupX, kScreenGroupY);
        });
    bb.put(res::kLit, io->lit);
  }

 private:
  static constexpr const char* kShader = "lighting: lighting.comp";
  // The lighting.comp specialization constants of one configuration, by constant_id.
  using Variant = std::vector<uint32_t>;

  // The constant_id lighting.comp gives `name`.
  uint32_t constant(const char* name) const {
    for (const vk::SpecializationConstant& c : constants_)
      if (c.name == name) return c.id;
    throw Error(ErrorKind::ShaderInterface, "",
                std::string(kShader) + " declares no specialization constant '" + name + "'");
  }

  // Where `resource` is in kLightingInputs.
  static size_t input(const char* resource) {
    for (size_t i = 0; i < kLightingInputs.size(); ++i)
      if (std::string_view(kLightingInputs[i].resource) == resource) return i;
    throw Error(ErrorKind::Usage, "", std::string("lighting: no optional input ") + resource);
  }

  // The pipeline for this frame's lights, PCF radius, optional inputs (mode per input: 0
  // fallback, 1 same size, 2 other size) and environment kind, built on first use: a scene
  // needs one or two, and the disk pipeline cache keeps them between runs.
  const vk::Pipeline& variant(const std::array<uint32_t, kLightingInputs.size()>& inputs) {
    uint32_t types = 0, shadowTypes = 0;
    for (const GpuLight& l : s_.lights.lights) {
      const uint32_t bit = 1u << std::clamp(int(l.directionType.w), 0, 2);
      types |= bit;
      if (l.shadow.x >= 0.0f) shadowTypes |= bit;
    }
    // Sized by the constants set here (the shader's others, e.g. guards.glsl's, keep their
    // defaults and are not part of the key).
    uint32_t size = 0;
    for (const char* name : {"kLightTypes", "kShadowTypes", "kPcfRadius", "kEnvironmentKind"})
      size = std::max(size, constant(name) + 1);
    for (const LightingInput& in : kLightingInputs)
      size = std::max(size, constant(in.constant) + 1);
    Variant key(size, 0u);
    key[constant("kLightTypes")] = types;
    key[constant("kShadowTypes")] = shadowTypes;
    key[constant("kPcfRadius")] = std::min(s_.settings.pcfRadius, 3u);
    key[constant("kEnvironmentKind")] = s_.environment.kind();
    for (size_t i = 0; i < kLightingInputs.size(); ++i)
      key[constant(kLightingInputs[i].constant)] = inputs[i];
    auto found = pipelines_.find(key);
    if (found != pipelines_.end()) return found->second;
    return pipelines_.emplace(key, vk::Pipeline::compute(s_.ctx, {kShader, spirv_, key}))
        .first->second;
  }

  EngineState& s_;
  std::vector<uint32_t> spirv_;                        // lighting.comp
  std::vector<vk::SpecializationConstant> constants_;  // its reflection, by constant_id
  std::map<Variant, vk::Pipeline> pipelines_;
};

}  // namespace

std::unique_ptr<Effect> makeLightingPass(EngineState& state) {
  return std::make_unique<LightingPass>(state);
}

}  // namespace gi
