#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "guards.glsl"

// Lighting composition from the G-buffer: emission + direct light (Lambert + normalised
// Blinn-Phong, PCF shadow maps) + the environment term + indirect light. The environment term
// is the engine's SH9 irradiance x albedo x ambient visibility ("ao"), unless an effect supplies
// its replacement ("ambient", alpha 1: directional occlusion; alpha 2: the same per unit diffuse
// albedo, multiplied here); "indirect" is added. All three
// optional inputs default to neutral 1x1 textures (ao 1, ambient alpha 0, indirect 0); a fourth,
// "contact_shadow" (1), scales the first four shadowed lights' shadow factors; a fifth,
// "direct_light", replaces the evaluation of the lights (sumLights, lights.glsl).
// Workgroup 32x16 (kScreenGroupX/Y in passes/builtin_passes.h): llvmpipe pays per workgroup.
layout(local_size_x = 32, local_size_y = 16) in;

// What this frame needs, fixed when the pipeline is built (LightingPass::Variant): llvmpipe runs
// every branch of an `if` for every pixel, so code for absent light types, inputs and
// environment kinds is removed here rather than skipped at run time.
layout(constant_id = 0) const int kLightTypes = 7;   // bit mask: 1 directional, 2 point, 4 spot
layout(constant_id = 1) const int kShadowTypes = 7;  // the same for shadowed lights
layout(constant_id = 2) const int kPcfRadius = 1;    // engine.pcf_radius
// Optional inputs: 0 the neutral fallback (not read), 1 full resolution (one texelFetch),
// 2 another size (bilinear).
layout(constant_id = 3) const int kAoInput = 0;
layout(constant_id = 4) const int kAmbientInput = 0;
layout(constant_id = 5) const int kIndirectInput = 0;
layout(constant_id = 6) const int kEnvironmentKind = 0;  // 0 sky, 1 constant, 2 equirect map
// "contact_shadow" (same modes): channel i multiplies the shadow factor of the i-th
// shadow-casting light, the first four in `lights` order.
layout(constant_id = 7) const int kContactInput = 0;
// "direct_light" (same modes): the lights' radiance an effect computed already (e.g. for its
// own use); it replaces this pass's evaluation of the lights (and with it the contact input).
layout(constant_id = 8) const int kDirectInput = 0;
#define GI_LIGHT_TYPES kLightTypes
#define GI_SHADOW_TYPES kShadowTypes
#define GI_PCF_RADIUS kPcfRadius

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Bindings 1-5: gi::LitSurfaceInputs (the G-buffer, the lights, the shadow maps).
#define GI_DEPTH_BINDING 1
#define GI_GBUFFER_BINDING 2
#include "gbuffer.glsl"
#define GI_LIGHTS_SET 0
#define GI_LIGHTS_BINDING 3
#define GI_SHADOW_VIEWS_BINDING 4
#define GI_SHADOW_MAPS_BINDING 5
#include "lights.glsl"
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D outLit;
layout(set = 0, binding = 7) uniform sampler2D aoTexture;       // linear, any size
layout(set = 0, binding = 8) uniform sampler2D ambientTexture;  // linear, any size
layout(set = 0, binding = 9) uniform sampler2D indirectTexture;  // linear, any size
// Equirect environment map (kind 2; a 1x1 dummy otherwise).
layout(set = 0, binding = 10) uniform sampler2D environmentMap;
layout(set = 0, binding = 11) uniform sampler2D contactTexture;  // linear, any size
layout(set = 0, binding = 12) uniform sampler2D directTexture;   // linear, any size

const float PI = 3.14159265358979;

vec4 optionalInput(sampler2D t, int mode, ivec2 p, vec2 uv) {
  return mode == 1 ? texelFetch(t, p, 0) : textureLod(t, uv, 0.0);
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  vec2 uv = (vec2(p) + 0.5) * frame.viewport.zw;
  float depth = giGBufferDepth(p);

  if (isSky(depth)) {
    vec3 viewDirWorld = safeNormalize(
        mat3(frame.invView) * viewPositionFromDepth(frame.invProj, uv, 0.5), vec3(0, 0, -1));
    vec3 sky;
    if (kEnvironmentKind == 2)
      sky = textureLod(environmentMap, equirectUV(viewDirWorld), 0.0).rgb * frame.skyZenith.w;
    else if (kEnvironmentKind == 1)
      sky = frame.skyGround.rgb * frame.skyZenith.w;
    else
      sky = proceduralSkyRadiance(frame, viewDirWorld);
    imageStore(outLit, p, vec4(giClampRadianceCounted(sky), 1.0));
    return;
  }
  vec3 pos = viewPositionFromDepth(frame.invProj, uv, depth);
  uvec4 g = giGBufferLoad(p);  // the whole surface in one fetch
  vec3 n = giGBufferNormal(g);
  vec3 albedo = giGBufferAlbedo(g);
  vec3 emission = giGBufferEmission(g);
  float metallic = giGBufferMetallic(g);
  vec3 v = safeNormalizeCounted(-pos, vec3(0, 0, 1));
  vec3 diffuseColor = albedo * (1.0 - metallic);

  vec3 color = emission;
  if (kDirectInput != 0) {
    color += max(optionalInput(directTexture, kDirectInput, p, uv).rgb, vec3(0.0));
  } else {
    vec4 contact =
        kContactInput != 0 ? optionalInput(contactTexture, kContactInput, p, uv) : vec4(1.0);
    LightSum lightSum = sumLights(pos, n, v, mix(vec3(0.04), albedo, metallic),
                                  shininessOf(giGBufferRoughness(g)), contact, kContactInput != 0);
    color += diffuseColor * lightSum.irradiance * (1.0 / PI) + lightSum.specular;
  }
  vec4 ambient = kAmbientInput != 0 ? optionalInput(ambientTexture, kAmbientInput, p, uv) : vec4(0.0);
  if (ambient.a > 0.5) {
    // alpha 2: the effect left the diffuse albedo to this pass, which reads it anyway.
    color += max(ambient.rgb, vec3(0.0)) * (ambient.a > 1.5 ? diffuseColor : vec3(1.0));
  } else {
    vec3 nWorld = mat3(frame.invView) * n;
    float ao = kAoInput != 0 ? clamp(optionalInput(aoTexture, kAoInput, p, uv).r, 0.0, 1.0) : 1.0;
    color += diffuseColor * environmentIrradianceOverPi(frame, nWorld) * ao;
  }
  if (kIndirectInput != 0)
    color += max(optionalInput(indirectTexture, kIndirectInput, p, uv).rgb, vec3(0.0));
  imageStore(outLit, p, vec4(giClampRadianceCounted(color), 1.0));
}
