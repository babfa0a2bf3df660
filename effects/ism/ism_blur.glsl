// Included by ism_blur_x.comp / ism_blur_y.comp (AXIS 0 / 1). Geometry-aware blur removing the K x K block pattern (seed 002 §3.4): along x (AXIS 0) then
// y (AXIS 1), taps LO..HI around the pixel (K taps cover every phase once; the blur_radius
// setting widens it), averaging only neighbours within the tolerance (x view distance) of the centre's
// tangent plane and whose normal is close. AXIS 1 then reflects: indirect = diffuse albedo / pi x irradiance.
// SCALE > 1 (gathered at 1 / SCALE resolution): runs at that resolution, and AXIS 1 with LOW
// defined keeps the raw layout (irradiance, distance, normal) for ism_upsample.comp instead.
// GLOSSY: x, y are RGB9E5 irradiance and Phong-weighted irradiance (ism_glossy.glsl); AXIS 1
// adds f0 x the latter (f0 as the lighting pass: mix(0.04, albedo, metallic)).
#include "common.glsl"
#include "ism_common.glsl"
#include "ism_glossy.glsl"
#include "normal_codec.glsl"  // the raw texel's normal

layout(constant_id = 0) const int LO = -2;
layout(constant_id = 1) const int HI = 1;
layout(constant_id = 2) const int SCALE = 1;
layout(constant_id = 3) const bool GLOSSY = false;
layout(local_size_x = 32, local_size_y = 16) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 2) uniform usampler2D inRaw;
#if AXIS == 0 || defined(LOW)
layout(set = 0, binding = 3, rgba32ui) uniform writeonly uimage2D outRaw;
#else
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"  // the packed G-buffer (albedo, metallic)
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D outIndirect;
// An earlier effect's "indirect" (1x1 0 when none), added: ISM is its far field.
layout(set = 0, binding = 8) uniform sampler2D priorIndirect;
#endif

vec3 unpackValue(uvec4 t) {
  return GLOSSY ? ismUnpackRgb9e5(t.x) : vec3(unpackHalf2x16(t.x), unpackHalf2x16(t.y).x);
}

// View-space position of pixel q at view distance `dist`.
vec3 viewPoint(ivec2 q, float dist) {
  vec2 uv = (vec2(min(q * SCALE, ivec2(frame.viewport.xy) - 1)) + 0.5) * frame.viewport.zw;
  return normalize(viewPositionFromDepth(frame.invProj, uv, 0.5)) * dist;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = textureSize(inRaw, 0);  // the viewport / SCALE, rounded
  if (p.x >= size.x || p.y >= size.y) return;
  uvec4 c = texelFetch(inRaw, p, 0);
  float z = uintBitsToFloat(c.z);
  vec3 n = giDecodeNormal(c.w);
  vec3 centre = viewPoint(p, z);
  vec3 sum = vec3(0.0), specSum = vec3(0.0);
  float wsum = 0.0;
  ivec2 axis = AXIS == 0 ? ivec2(1, 0) : ivec2(0, 1);
  for (int o = LO; o <= HI; ++o) {
    ivec2 q = clamp(p + axis * o, ivec2(0), size - 1);
    uvec4 t = texelFetch(inRaw, q, 0);
    float zt = uintBitsToFloat(t.z);
    // Same surface: the neighbour lies near the centre's tangent plane and faces alike.
    float plane = abs(dot(n, viewPoint(q, zt) - centre));
    float w = (zt > 0.0 && plane <= ism.blur.x * z && dot(giDecodeNormal(t.w), n) >= ism.blur.y)
                  ? 1.0 : 0.0;
    sum += w * unpackValue(t);
    if (GLOSSY) specSum += w * ismUnpackRgb9e5(t.y);
    wsum += w;
  }
  vec3 e = z > 0.0 ? sum / max(wsum, 1.0) : vec3(0.0);
  vec3 spec = z > 0.0 ? specSum / max(wsum, 1.0) : vec3(0.0);
#if AXIS == 0 || defined(LOW)
  uvec2 value = GLOSSY ? uvec2(ismPackRgb9e5(e), ismPackRgb9e5(spec))
                       : uvec2(packHalf2x16(e.rg), packHalf2x16(vec2(e.b, 0.0)));
  imageStore(outRaw, p, uvec4(value, c.z, c.w));
#else
  uvec4 surface = giGBufferLoad(p);
  vec3 albedo = giGBufferAlbedo(surface);
  float metallic = giGBufferMetallic(surface);
  vec3 diffuse = albedo * (1.0 - metallic);
  vec3 l = diffuse * e / 3.14159265;
  if (GLOSSY) l += mix(vec3(0.04), albedo, metallic) * spec;
  l += max(textureLod(priorIndirect, (vec2(p) + 0.5) * frame.viewport.zw, 0.0).rgb, vec3(0.0));
  imageStore(outIndirect, p, vec4(min(l, vec3(65000.0)), 1.0));
#endif
}
