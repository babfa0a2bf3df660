#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "guards.glsl"

// transfer = radiance: per pixel, once, the radiance an occluder at this pixel sends besides its
// share of the ambient light (seed 001 §3: "the radiance stored in the pixel"): emission +
// diffuse albedo x the scene's lights (irradiance / pi, summed by the engine's sumLights exactly
// as the lighting pass sums them: shadow maps, PCF). Lambertian: no specular. This frame's lit
// image does not exist yet (the effect runs before lighting) and the ambient part is the
// transfer's own unknown (eq. 9's denominator), so it is left out here. Having summed the
// lights, it also publishes their full radiance (specular included) as "direct_light", which
// the lighting pass then uses instead of summing them a second time (as SSDO's bounce does).
layout(local_size_x = 32, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Bindings 1-5: gi::LitSurfaceInputs.
#define GI_DEPTH_BINDING 1
#define GI_GBUFFER_BINDING 2
#include "gbuffer.glsl"
#define GI_LIGHTS_SET 0
#define GI_LIGHTS_BINDING 3
#define GI_SHADOW_VIEWS_BINDING 4
#define GI_SHADOW_MAPS_BINDING 5
#include "lights.glsl"
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D outRadiance;
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D outDirect;  // "direct_light"

// Guard: half floats overflow to inf above 65504.
const float kMaxRadiance = 65000.0;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;

  float depth = giGBufferDepth(p);
  uvec4 g = giGBufferLoad(p);
  // Guard: sky / far-plane pixels and pixels without geometry send nothing (they are never
  // inside a test anyway: their depth is behind every point).
  if (isSky(depth) || !giGBufferIsGeometry(g)) {
    imageStore(outRadiance, p, vec4(0.0));
    imageStore(outDirect, p, vec4(0.0, 0.0, 0.0, 1.0));  // the lighting pass draws the sky
    return;
  }
  vec2 uv = (vec2(p) + 0.5) * frame.viewport.zw;
  vec3 pos = viewPositionFromDepth(frame.invProj, uv, depth);
  vec3 n = giGBufferNormal(g);
  vec3 albedo = giGBufferAlbedo(g);
  float metallic = giGBufferMetallic(g);
  LightSum lights = sumLights(pos, n, safeNormalize(-pos, vec3(0.0, 0.0, 1.0)),
                              mix(vec3(0.04), albedo, metallic),
                              shininessOf(giGBufferRoughness(g)), vec4(1.0), false);
  vec3 diffuseDirect = albedo * (1.0 - metallic) * lights.irradiance * (1.0 / 3.14159265358979);
  vec3 radiance = giGBufferEmission(g) + diffuseDirect;
  vec3 direct = diffuseDirect + lights.specular;
  // Guards: finite, non-negative, below the half-float maximum; NaN inputs read 0.
  giGuard(GI_GUARD_NONFINITE, any(isnan(radiance)) || any(isnan(direct)));
  giGuard(GI_GUARD_RANGE, any(greaterThan(max(radiance, direct), vec3(kMaxRadiance))));
  radiance = clamp(radiance, vec3(0.0), vec3(kMaxRadiance));
  radiance = mix(radiance, vec3(0.0), isnan(radiance));
  direct = clamp(direct, vec3(0.0), vec3(kMaxRadiance));
  direct = mix(direct, vec3(0.0), isnan(direct));
  imageStore(outRadiance, p, vec4(radiance, 1.0));
  imageStore(outDirect, p, vec4(direct, 1.0));
}
