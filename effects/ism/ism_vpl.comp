#version 460
// VPLs by importance sampling the reflective shadow map's flux (seed 002 §3.3): one workgroup
// builds the CDF of the texels' flux (r + g + b) with a parallel prefix sum, then places VPL i
// at u_i = (i + jitter_i) / N (stratified, a fixed jitter per i: static lights give the same
// VPLs every frame) by binary search. VPL flux = texel flux / (N pdf). An all-black map (light
// facing away, no light) has an empty CDF: every VPL gets flux 0 and w = 0 (guard).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "ism_common.glsl"

layout(local_size_x = 256) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 2) uniform sampler2D rsmPosition;
layout(set = 0, binding = 3) uniform sampler2D rsmNormal;
layout(set = 0, binding = 4) uniform sampler2D rsmFlux;
layout(set = 0, binding = 5, std430) buffer Cdf { float cdf[]; };
layout(set = 0, binding = 6, std430) writeonly buffer Vpls { Vpl vpls[]; };

shared float partial[256];

ivec2 texelOf(int i, int w) { return ivec2(i % w, i / w); }

void main() {
  int w = int(ism.rsm.x), h = int(ism.rsm.y), total = w * h;
  int t = int(gl_LocalInvocationID.x);
  int chunk = (total + 255) / 256;
  int begin = min(t * chunk, total), end = min(begin + chunk, total);
  float run = 0.0;
  for (int i = begin; i < end; ++i) {
    vec3 f = max(texelFetch(rsmFlux, texelOf(i, w), 0).rgb, vec3(0.0));
    float v = f.r + f.g + f.b;
    run += (isnan(v) || isinf(v)) ? 0.0 : v;  // guard: a bad texel never enters the CDF
    cdf[i] = run;
  }
  partial[t] = run;
  barrier();
  // Hillis-Steele inclusive scan of the 256 chunk sums.
  for (int off = 1; off < 256; off <<= 1) {
    float add = t >= off ? partial[t - off] : 0.0;
    barrier();
    partial[t] += add;
    barrier();
  }
  float base = t > 0 ? partial[t - 1] : 0.0;
  for (int i = begin; i < end; ++i) cdf[i] += base;
  memoryBarrierBuffer();
  barrier();
  float sum = partial[255];
  int n = int(ism.rsm.z), padded = int(ism.rsm.w);
  for (int i = t; i < padded; i += 256) {
    Vpl v;
    v.position = vec4(0.0);
    v.normal = vec4(0.0, 1.0, 0.0, 0.0);
    v.flux = vec4(0.0);
    if (i < n && sum > 1e-30) {
      float u = (float(i) + float(ismHash(uint(i) * 747796405u + 1u) >> 8) / 16777216.0) /
                float(n);
      float target = u * sum;
      int lo = 0, hi = total - 1;  // smallest j with cdf[j] > target
      while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] > target) hi = mid; else lo = mid + 1;
      }
      float p = cdf[lo] - (lo > 0 ? cdf[lo - 1] : 0.0);
      ivec2 tx = texelOf(lo, w);
      vec4 pos = texelFetch(rsmPosition, tx, 0);
      if (p > 0.0 && pos.w > 0.5) {
        vec3 f = max(texelFetch(rsmFlux, tx, 0).rgb, vec3(0.0));
        vec3 nrm = safeNormalize(texelFetch(rsmNormal, tx, 0).xyz, vec3(0.0, 1.0, 0.0));
        // Lifted off its surface by 1e-3 of the scene extent: the surface it sits on then lies
        // behind its hemisphere (a paraboloid map would otherwise stretch that surface's
        // triangles over the whole disk).
        v.position = vec4(pos.xyz + nrm * (1e-3 * ism.pull.w), 1.0);
        v.normal = vec4(nrm, 0.0);
        v.flux = vec4(f * (sum / (p * float(n))), 0.0);
      }
    }
    vpls[i] = v;
  }
}
