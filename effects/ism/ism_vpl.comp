#version 460
// First-bounce VPLs by importance sampling the reflective shadow map's flux (seed 002 §3.3),
// the texels' r + g + b (ism_sample.glsl). An all-black map (light facing away, no light) has an
// empty CDF: every VPL gets flux 0 and w = 0 (guard). Also zeroes the table's padding.
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

#include "ism_sample.glsl"

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
  float sum = ismScan(run, begin, end);
  int n = int(ism.rsm.z), padded = int(ism.rsm.w);
  for (int i = t; i < padded; i += 256) {
    Vpl v;
    v.position = vec4(0.0);
    v.normal = vec4(0.0, 1.0, 0.0, 0.0);
    v.flux = vec4(0.0);
    if (i < n && sum > 1e-30) {
      float p;
      int lo = ismPick(i, n, total, sum, p);
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
        v.flux = vec4(f / (p * float(n)), 0.0);
      }
    }
    vpls[i] = v;
  }
}
