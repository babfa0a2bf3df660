// "lighting": composes the lit image from the G-buffer, the lights and shadow maps, the
// environment and the optional inputs effects publish (ao, ambient, indirect, contact_shadow,
// direct_light; neutral when absent: the fallbacks are declared once, in the renderer's
// buildGraph()).
#include <algorithm>
#include <array>
#include <map>

#include "gi/errors.h"
#include "gi/lit_surface.h"
#include "gi/vk/pipeline.h"
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
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    struct Io {
      LitSurfaceInputs surface;  // the G-buffer and the lights (gi/lit_surface.h)
      TextureHandle ao, ambient, indirect, contact, direct, environment, lit;
      // ao, ambient, indirect, contact_shadow, direct_light: the neutral stand-in
      bool fallback[5] = {true, true, true, true, true};
    };
    auto io = std::make_shared<Io>();

    Blackboard& bb = graph.blackboard();
    graph.addPass(
        "lighting",
        [&](PassBuilder& b) {
          io->surface.read(b, bb);
          io->ao = b.readOptional(res::kAO);
          io->ambient = b.readOptional(res::kAmbient);
          io->indirect = b.readOptional(res::kIndirect);
          io->fallback[0] = b.isFallback(io->ao);
          io->fallback[1] = b.isFallback(io->ambient);
          io->fallback[2] = b.isFallback(io->indirect);
          io->contact = b.readOptional(res::kContactShadow);
          io->fallback[3] = b.isFallback(io->contact);
          io->direct = b.readOptional(res::kDirectLight);
          io->fallback[4] = b.isFallback(io->direct);
          // The contact factors multiply single lights' shadows; a published direct_light has
          // summed the lights already, so whoever publishes it must have applied them.
          if (!io->fallback[3] && !io->fallback[4])
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
          auto inputMode = [&](bool isFallback, TextureHandle h) {
            if (isFallback) return 0u;
            const VkExtent2D i = pc.extent(h);
            return i.width == e.width && i.height == e.height ? 1u : 2u;
          };
          const vk::Pipeline& pipeline = variant(
              {inputMode(io->fallback[0], io->ao), inputMode(io->fallback[1], io->ambient),
               inputMode(io->fallback[2], io->indirect), inputMode(io->fallback[3], io->contact),
               inputMode(io->fallback[4], io->direct)});
          vk::DescriptorWriter w(pipeline);
          w.buffer("Frame", frame);
          io->surface.bind(w, pc, nearest);
          w.image("outLit", pc.view(io->lit))
              .texture("aoTexture", pc.view(io->ao), linear)
              .texture("ambientTexture", pc.view(io->ambient), linear)
              .texture("indirectTexture", pc.view(io->indirect), linear)
              .texture("environmentMap", pc.view(io->environment), s_.scene.linearRepeat())
              .texture("contactTexture", pc.view(io->contact), linear)
              .texture("directTexture", pc.view(io->direct), linear);
          pc.dispatch(pipeline, w, e, kScreenGroupX, kScreenGroupY);
        });
    bb.put(res::kLit, io->lit);
  }

 private:
  // The lighting.comp specialization constants of one configuration (constant_id order).
  using Variant = std::array<uint32_t, 9>;

  // The pipeline for this frame's lights, PCF radius, optional inputs (mode per input: 0
  // fallback, 1 same size, 2 other size) and environment kind, built on first use: a scene
  // needs one or two, and the disk pipeline cache keeps them between runs.
  const vk::Pipeline& variant(const std::array<uint32_t, 5>& inputs) {
    uint32_t types = 0, shadowTypes = 0;
    for (const GpuLight& l : s_.lights.lights) {
      const uint32_t bit = 1u << std::clamp(int(l.directionType.w), 0, 2);
      types |= bit;
      if (l.shadow.x >= 0.0f) shadowTypes |= bit;
    }
    const Variant key{types,
                      shadowTypes,
                      std::min(s_.settings.pcfRadius, 3u),
                      inputs[0],
                      inputs[1],
                      inputs[2],
                      s_.environment.kind(),
                      inputs[3],
                      inputs[4]};
    auto found = pipelines_.find(key);
    if (found != pipelines_.end()) return found->second;
    return pipelines_
        .emplace(key, vk::Pipeline::compute(s_.ctx, {"lighting: lighting.comp",
                                                     vk::loadSpirv("lighting.comp"),
                                                     {key.begin(), key.end()}}))
        .first->second;
  }

  EngineState& s_;
  std::map<Variant, vk::Pipeline> pipelines_;
};

}  // namespace

std::unique_ptr<Effect> makeLightingPass(EngineState& state) {
  return std::make_unique<LightingPass>(state);
}

}  // namespace gi
