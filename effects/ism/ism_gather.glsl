// Interleaved gathering (seed 002 §3.4, after Segovia et al. 2006). Workgroup layer z is the
// phase (x % K, y % K) of a K x K block: its pixels gather only VPLs phase + j K^2, so the VPL
// index is uniform in the workgroup (one uniform-buffer load, not one per lane) and each pixel
// sums N / K^2 VPLs, weighted K^2; the blur averages the K^2 phases back. Per VPL: irradiance
// phi / pi cos cos / max(d^2, d_min^2) (the singularity guard), visibility from the VPL's map
// with a constant + slope bias. Output texel (RGBA32UI): x, y irradiance (half rg, half b),
// z view distance (float bits, 0: sky), w view normal (octahedral snorm 16x2).
// ISM_CLASSIC: the maps are accurate paraboloid depth maps (D32 reverse-Z, near..far).
// SCALE > 1: gathered at 1 / SCALE resolution, output pixel p for G-buffer pixel p x SCALE
// (ism_upsample.comp brings it back to full resolution).
// GLOSSY: x, y are RGB9E5 irradiance and its Phong-weighted sum (ism_glossy.glsl).
// ENV_PER_PIXEL > 0: environment VPLs (ism_env_vpl.comp) too, interleaved the same way (pixel
// phase gathers env VPLs phase + j K^2), E_i max(n.d_i, 0) x visibility from their
// orthographic maps beyond the near field, x "ao" within it; `strength` scales the VPLs'
// indirect light, not the environment's.
#include "common.glsl"
#include "ism_common.glsl"
#include "ism_glossy.glsl"

layout(constant_id = 0) const int PER_PIXEL = 16;  // ceil(N / K^2)
layout(constant_id = 1) const int K = 4;
layout(constant_id = 2) const int SCALE = 1;
layout(constant_id = 3) const bool GLOSSY = false;
layout(constant_id = 4) const float PHONG_EXPONENT = 0.0;  // 0: from the roughness
layout(constant_id = 5) const int ENV_PER_PIXEL = 0;       // ceil(N_env / K^2)
layout(local_size_x = 32, local_size_y = 16) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 2, std140) uniform Vpls { Vpl vpls[ISM_VPL_SLOTS]; };
layout(set = 0, binding = 3) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 4
#include "gbuffer.glsl"  // the packed G-buffer (normal; roughness when GLOSSY)
#include "ism_lookup.glsl"
layout(set = 0, binding = 6, rgba32ui) uniform writeonly uimage2D outRaw;
layout(set = 0, binding = 8, std140) uniform EnvVpls { Vpl envVpls[ISM_VPL_SLOTS]; };
// "ao" of an AO effect (its neutral 1x1 when none; any size, linear): the environment VPLs'
// visibility within its range, multiplying their light (ism_lookup.glsl: the maps count only
// occluders beyond it).
layout(set = 0, binding = 9) uniform sampler2D aoTexture;

// The receiver's BRDF (diffuse, + Phong when GLOSSY): adds VPL v's irradiance at x to e and,
// when glossy, its Phong-weighted share to spec (view: unit direction to the camera).
void reflectVpl(Vpl v, uint tile, vec3 x, vec3 n, vec3 view, float exponent, inout vec3 e,
                inout vec3 spec) {
  vec3 ei = vplIrradiance(v, tile, x, n);
  e += ei;
  if (GLOSSY) spec += ei * ismPhongLobe(x - v.position.xyz, n, view, exponent);
}


void main() {
  uint phase = gl_WorkGroupID.z;
  ivec2 p = ivec2(gl_GlobalInvocationID.xy) * K + ivec2(int(phase) % K, int(phase) / K);
  ivec2 size = imageSize(outRaw);  // the viewport / SCALE, rounded
  if (p.x >= size.x || p.y >= size.y) return;
  ivec2 g = min(p * SCALE, ivec2(frame.viewport.xy) - 1);  // the G-buffer pixel it stands for
  float depth = texelFetch(gDepth, g, 0).r;
  if (isSky(depth)) {
    imageStore(outRaw, p, uvec4(0u));
    return;
  }
  vec2 uv = (vec2(g) + 0.5) * frame.viewport.zw;
  vec3 viewPos = viewPositionFromDepth(frame.invProj, uv, depth);
  uvec4 surface = giGBufferLoad(g);
  vec3 viewN = giGBufferNormal(surface);
  vec3 x = (frame.invView * vec4(viewPos, 1.0)).xyz;
  vec3 n = safeNormalize(mat3(frame.invView) * viewN, vec3(0.0, 1.0, 0.0));
  vec3 e = vec3(0.0), spec = vec3(0.0);
  vec3 view = safeNormalize(mat3(frame.invView) * -viewPos, n);
  float exponent = GLOSSY ? ismPhongExponent(PHONG_EXPONENT, giGBufferRoughness(surface)) : 1.0;
  for (int j = 0; j < PER_PIXEL; ++j) {
    uint i = phase + uint(j * K * K);
    Vpl v = vpls[i];
    // Near field: the first bounce's light from senders within ism.nearField.y is an earlier
    // effect's "indirect" (added after the blur); later bounces are all ISM's.
    if (float(i) >= ism.rsm.z || distance(v.position.xyz, x) >= ism.nearField.y)
      reflectVpl(v, min(i, uint(ism.blur.w) - 1u), x, n, view, exponent, e, spec);
  }
  vec3 envE = vec3(0.0), envSpec = vec3(0.0);
  for (int j = 0; j < ENV_PER_PIXEL; ++j) {
    uint i = phase + uint(j * K * K);
    Vpl v = envVpls[i];
    vec3 ei = envVplIrradiance(v, uint(ism.envVpls.z) + i, x, n);
    envE += ei;
    if (GLOSSY) envSpec += ei * ismPhongLobe(-v.position.xyz, n, view, exponent);
  }
  if (ENV_PER_PIXEL > 0) {
    float ao = clamp(textureLod(aoTexture, uv, 0.0).r, 0.0, 1.0);
    envE *= ao;
    envSpec *= ao;
  }
  // guard: half floats
  e = min(e * (ism.gather.z * ism.gather.w) + envE * ism.gather.z, vec3(65000.0));
  spec = min(spec * (ism.gather.z * ism.gather.w) + envSpec * ism.gather.z, vec3(65000.0));
  uvec2 value = GLOSSY ? uvec2(ismPackRgb9e5(e), ismPackRgb9e5(spec))
                       : uvec2(packHalf2x16(e.rg), packHalf2x16(vec2(e.b, 0.0)));
  imageStore(outRaw, p, uvec4(value, floatBitsToUint(length(viewPos)), giEncodeNormal(viewN)));
}
