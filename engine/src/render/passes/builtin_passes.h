// The engine's own passes, each a gi::Effect on the same API as the plugins (declared reads
// and writes, checked like theirs; frame-graph passes added in addPasses). The renderer
// orchestrates them (renderer.cpp); what they share with it is EngineState.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "gi/effect.h"
#include "gi/renderer.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "render/environment_gpu.h"
#include "render/light_setup.h"
#include "render/scene_gpu.h"
#include "render/surface_points_pass.h"

namespace gi {

// Owned by the renderer; the passes keep a reference. (The passes build their EffectInfo by
// aggregate initialisation: GCC 12 at -O3 warns, -Wrestrict, on assigning short literals.)
struct EngineState {
  vk::Context& ctx;
  RenderSettings& settings;
  SceneGpu& scene;
  LightSetup& lights;
  EnvironmentGpu& environment;
  std::unique_ptr<SurfacePointsPass>& surfacePoints;
  vk::Image& output;  // the tonemapped RGBA8 image (imported as "output")
  VkSampler nearest, linear;
  uint32_t skinnedThisFrame = 0;         // written by the skinning pass
  LightBuffers* lightBuffers = nullptr;  // the shadow pass rewrites the views of maps it keeps
  // Shadow maps this frame drawn whole (or their cache built) and restored from their cache.
  uint32_t shadowMapsDrawn = 0, shadowMapsCached = 0;
};

std::unique_ptr<Effect> makeSkinningPass(EngineState& state);
std::unique_ptr<Effect> makeGBufferPass(EngineState& state);
std::unique_ptr<Effect> makeSurfacePointsPass(EngineState& state);
std::unique_ptr<Effect> makeShadowPass(EngineState& state);
std::unique_ptr<Effect> makeLightingPass(EngineState& state);
std::unique_ptr<Effect> makeTonemapPass(EngineState& state);
std::unique_ptr<Effect> makeFloorPass(EngineState& state);

// The lighting pass's optional inputs, in this one table: the blackboard resource an effect may
// publish, the 1x1 neutral texture that stands in when none does (its format and value: the
// renderer declares it), and the names lighting.comp gives its sampler and the specialization
// constant that says whether it is absent (0: its fetch compiled out), of the output's size (1:
// one texel fetch) or of another size (2: bilinear). The pass finds both in the shader's own
// reflection (constant ids live only in GLSL) and refuses a shader that lacks one.
struct LightingInput {
  const char* resource;
  VkFormat format;
  std::array<float, 4> neutral;
  const char* texture;
  const char* constant;
  const char* does;      // what lighting.comp does with it, for errors
  const char* maskedBy;  // the input that, published, leaves this one unused ("" none)
};
inline const std::array<LightingInput, 5> kLightingInputs = {{
    {resources::kAO,
     VK_FORMAT_R8G8B8A8_UNORM,
     {1.0f, 1.0f, 1.0f, 1.0f},
     "aoTexture",
     "kAoInput",
     "multiplies the environment term",
     resources::kAmbient},
    {resources::kAmbient,
     VK_FORMAT_R16G16B16A16_SFLOAT,
     {},
     "ambientTexture",
     "kAmbientInput",
     "replaces the environment term",
     ""},
    {resources::kIndirect,
     VK_FORMAT_R16G16B16A16_SFLOAT,
     {},
     "indirectTexture",
     "kIndirectInput",
     "adds indirect light",
     ""},
    {resources::kContactShadow,
     VK_FORMAT_R8G8B8A8_UNORM,
     {1.0f, 1.0f, 1.0f, 1.0f},
     "contactTexture",
     "kContactInput",
     "multiplies the lights' shadow factors",
     resources::kDirectLight},
    {resources::kDirectLight,
     VK_FORMAT_R16G16B16A16_SFLOAT,
     {},
     "directTexture",
     "kDirectInput",
     "replaces the lights' evaluation",
     ""},
}};

// Workgroup of the engine's full-screen compute passes (lighting, tonemap): llvmpipe
// pays a fixed cost per workgroup, so large groups are faster there (measured for SSAO).
inline constexpr uint32_t kScreenGroupX = 32, kScreenGroupY = 16;

// The shape tonemap, floor and the G-buffer unpacking share: a compute shader with the frame
// uniforms ("Frame"), one sampled input and one storage output (whatever their names),
// dispatched over the output in groupX x groupY workgroups (image_filter.cpp).
vk::Pipeline makeImageFilterPipeline(vk::Context& ctx, const std::string& spirvName,
                                     std::vector<uint32_t> specialization = {});
void recordImageFilter(PassContext& pc, const vk::Pipeline& pipeline, VkBuffer frame,
                       VkSampler sampler, TextureHandle in, TextureHandle out, uint32_t groupX,
                       uint32_t groupY);

}  // namespace gi
