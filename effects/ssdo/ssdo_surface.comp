#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "guards.glsl"

// Per pixel, once: what every SSDO tap reads at the pixel it lands on, in one texel
// (ssdo_common.glsl): 1 / view distance, the view normal and, with the bounce, the pixel's
// outgoing radiance as a sender. The lit image of this frame does not exist yet (SSDO runs
// before lighting) and the previous frame's is not kept, so the sender radiance is this
// frame's direct-light estimate: emission + diffuse albedo x (the lights, / pi + the engine's
// unoccluded environment irradiance / pi). Lambertian senders: no specular. The lights are
// summed exactly as the lighting pass sums them (sumLights, lights.glsl: PCF, contact shadows),
// and in the main view (kDirectOut) their full radiance, specular included, is published as
// "direct_light", which the lighting pass then uses instead of summing them again: with the
// bounce the lights are evaluated once per frame, as in the paper, whose bounce reads the
// direct-light buffer it has already rendered.
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const bool kBounce = true;
layout(constant_id = 1) const int kLightTypes = 7;   // bit mask: 1 directional, 2 point, 4 spot
layout(constant_id = 2) const int kShadowTypes = 7;  // the same for shadowed lights
// Depth layers (1 or 2): with 2, the peeled layer's 1 / view distance goes into the texel.
layout(constant_id = 3) const int kLayers = 1;
layout(constant_id = 4) const int kPcfRadius = 1;  // the engine's (frame.options.x), 0..3
// Main view with the bounce: write the lights' radiance to outDirect ("direct_light").
layout(constant_id = 5) const bool kDirectOut = false;
// The contact shadows (ssdo_contact.comp) multiply the first four shadowed lights.
layout(constant_id = 6) const bool kContactInput = false;
#define GI_LIGHT_TYPES kLightTypes
#define GI_SHADOW_TYPES kShadowTypes
#define GI_PCF_RADIUS kPcfRadius

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
#include "ssdo_common.glsl"
// Bindings 2-6: gi::LitSurfaceInputs (the main view's G-buffer, or a camera's).
#define GI_DEPTH_BINDING 2
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"
#define GI_LIGHTS_SET 0
#define GI_LIGHTS_BINDING 4
#define GI_SHADOW_VIEWS_BINDING 5
#define GI_SHADOW_MAPS_BINDING 6
#include "lights.glsl"
layout(set = 0, binding = 10, rgba32ui) uniform writeonly uimage2D outSurface;
layout(set = 0, binding = 11) uniform sampler2D gLayer1;  // the peeled layer (kLayers 2)
layout(set = 0, binding = 12, rgba16f) uniform writeonly image2D outDirect;  // kDirectOut
layout(set = 0, binding = 13) uniform sampler2D gContact;  // kContactInput: contact_shadow

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;

  float depth = giGBufferDepth(p);
  uvec4 g = giGBufferLoad(p);
  float p22 = frame.proj[2][2], p32 = frame.proj[3][2];
  // Reverse-Z depth to 1 / view distance: (d + P22) / P32 (affine in d). Guards: sky and
  // pixels without geometry read 0 (never an occluder); a degenerate projection gives 0.
  float iz = abs(p32) > 1e-30 ? (depth + p22) / p32 : 0.0;
  bool geometry = !isSky(depth) && giGBufferIsGeometry(g) && iz > 0.0 && !isinf(iz);
  iz = geometry ? iz : 0.0;
  vec3 n = giGBufferNormal(g);

  // Without kDirectOut the pass binds a 1x1 stand-in for outDirect (the cameras' pass): it is
  // written once, so that it never holds whatever its memory held before (the hard cases read
  // every texture back).
  if (!kDirectOut && p == ivec2(0)) imageStore(outDirect, p, vec4(0.0));

  vec3 radiance = vec3(0.0);
  if (kBounce) {
    vec2 uv = (vec2(p) + 0.5) * frame.viewport.zw;
    vec3 pos = viewPositionFromDepth(frame.invProj, uv, depth);
    vec3 albedo = giGBufferAlbedo(g);
    float metallic = giGBufferMetallic(g);
    vec3 diffuse = albedo * (1.0 - metallic);
    vec4 contact = kContactInput ? texelFetch(gContact, p, 0) : vec4(1.0);
    LightSum lightSum = sumLights(pos, n, safeNormalize(-pos, vec3(0.0, 0.0, 1.0)),
                                  mix(vec3(0.04), albedo, metallic),
                                  shininessOf(giGBufferRoughness(g)), contact,
                                  kContactInput);
    vec3 diffuseDirect = diffuse * lightSum.irradiance * (1.0 / 3.14159265358979);
    if (kDirectOut) {
      // Sky pixels: 0 (lighting writes the sky itself). Guard as below: finite, below the
      // half-float maximum.
      vec3 direct = geometry ? clamp(diffuseDirect + lightSum.specular, vec3(0.0), vec3(65000.0))
                             : vec3(0.0);
      direct = mix(direct, vec3(0.0), isnan(direct));
      imageStore(outDirect, p, vec4(direct, 1.0));
    }
    vec3 nWorld = mat3(frame.invView) * n;
    radiance = giGBufferEmission(g) + diffuseDirect + diffuse * ssdoIrradianceOverPi(nWorld);
    // Guard: half floats overflow to inf above 65504; non-finite inputs read 0.
    giGuard(GI_GUARD_NONFINITE, geometry && any(isnan(radiance)));
    giGuard(GI_GUARD_RANGE, geometry && any(greaterThan(radiance, vec3(65000.0))));
    radiance = geometry ? clamp(radiance, vec3(0.0), vec3(65000.0)) : vec3(0.0);
    radiance = vec3(isnan(radiance.r) ? 0.0 : radiance.r, isnan(radiance.g) ? 0.0 : radiance.g,
                    isnan(radiance.b) ? 0.0 : radiance.b);
  }
  // The second layer (GpuScene::drawDepthPeeled: strictly behind the first), as a half float:
  // 2^-11 relative, enough to tell a sample inside a solid from one behind it. Guard: none
  // there, or beyond the half range, reads 0 (no interval: the one-layer test).
  float iz1 = 0.0;
  if (kLayers > 1) {
    float d1 = texelFetch(gLayer1, p, 0).r;
    iz1 = abs(p32) > 1e-30 ? (d1 + p22) / p32 : 0.0;
    iz1 = geometry && d1 > 0.0 && iz1 > 0.0 && iz1 < 65000.0 ? iz1 : 0.0;
  }
  imageStore(outSurface, p,
             uvec4(floatBitsToUint(iz), giEncodeNormal(n), packHalf2x16(radiance.rg),
                   packHalf2x16(vec2(radiance.b, iz1))));
}
