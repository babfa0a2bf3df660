// Included by ism_bounce.comp / ism_bounce_classic.comp. The next bounce's VPLs (seed 002 §4,
// imperfect reflective shadow maps, here sampled at the points directly): SHADE surface points
// (the first of the engine's random-order points) are lit by the previous bounce's VPLs with
// their maps' visibility; each reflects albedo x E x the area it stands for; VPLs are
// importance-sampled from those fluxes (ism_sample.glsl) into the table's next N slots, whose
// maps the following passes splat (or draw). One workgroup.
#include "common.glsl"
#include "ism_common.glsl"

layout(constant_id = 0) const int N = 256;       // VPLs per bounce
layout(constant_id = 1) const int SHADE = 2048;  // shaded candidate points
layout(local_size_x = 256) in;
layout(push_constant) uniform Push { int bounce; };  // 1: bounce 2 from bounce 1, ...
layout(set = 0, binding = 2, std140) uniform Vpls { Vpl vpls[ISM_VPL_SLOTS]; };
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
struct Material {
  vec4 baseColor;
  vec4 emission;
  vec4 params;
};
layout(set = 0, binding = 4, std430) readonly buffer Materials { Material materials[]; };
#include "ism_lookup.glsl"
layout(set = 0, binding = 6, std430) buffer Cdf { float cdf[]; };  // SHADE cdf + SHADE x 4 flux
layout(set = 0, binding = 7, std430) writeonly buffer VplsOut { Vpl vplsOut[]; };

#include "ism_sample.glsl"

void main() {
  int t = int(gl_LocalInvocationID.x);
  uint count = uint(ism.atlas.w);
  int m = int(min(uint(SHADE), count));
  float represented = m > 0 ? float(count) / float(m) : 0.0;
  int chunk = (m + 255) / 256;
  int begin = min(t * chunk, m), end = min(begin + chunk, m);
  uint base = uint((bounce - 1) * N);
  float run = 0.0;
  for (int k = begin; k < end; ++k) {
    vec4 pa = points[2 * k], nm = points[2 * k + 1];
    vec3 e = vec3(0.0);
    for (int j = 0; j < N; ++j) e += vplIrradiance(vpls[base + uint(j)], base + uint(j), pa.xyz, nm.xyz);
    vec3 albedo = clamp(materials[int(nm.w)].baseColor.rgb, 0.0, 1.0);
    vec3 f = albedo * e * (pa.w * represented);
    float v = f.r + f.g + f.b;
    bool ok = !(isnan(v) || isinf(v));  // guard: a bad point never enters the CDF
    run += ok ? v : 0.0;
    cdf[k] = run;
    cdf[SHADE + 4 * k] = ok ? f.r : 0.0;
    cdf[SHADE + 4 * k + 1] = ok ? f.g : 0.0;
    cdf[SHADE + 4 * k + 2] = ok ? f.b : 0.0;
  }
  float sum = ismScan(run, begin, end);
  for (int i = t; i < N; i += 256) {
    Vpl v;
    v.position = vec4(0.0);
    v.normal = vec4(0.0, 1.0, 0.0, 0.0);
    v.flux = vec4(0.0);
    if (m > 0 && sum > 1e-30) {
      float p;
      int k = ismPick(i, N, m, sum, p);
      if (p > 0.0) {
        vec3 nrm = safeNormalize(points[2 * k + 1].xyz, vec3(0.0, 1.0, 0.0));
        v.position = vec4(points[2 * k].xyz + nrm * (1e-3 * ism.pull.w), 1.0);
        v.normal = vec4(nrm, 0.0);
        vec3 f = vec3(cdf[SHADE + 4 * k], cdf[SHADE + 4 * k + 1], cdf[SHADE + 4 * k + 2]);
        v.flux = vec4(f / (p * float(N)), 0.0);
      }
    }
    vplsOut[base + uint(N) + uint(i)] = v;
  }
}
