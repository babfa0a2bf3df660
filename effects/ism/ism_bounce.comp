#version 460
// The next bounce's VPLs from the previous bounce's imperfect reflective shadow maps (seed 002
// §4.1; ism_irsm.glsl shades them), importance-sampled with a marginal and a conditional CDF:
// VPL i's stratified target picks a cell (256 entries of one IRSM) from the running sum of the
// cells' sums (ism_sample.glsl), then the entry within the cell where the entries' running sum
// passes the rest of the target. It sits on that entry's point (lifted as ism_vpl.comp lifts
// its VPLs) with the entry's flux / (N p), p = entry / total. No flux anywhere (the empty CDF)
// places no VPL (guard). One workgroup.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "ism_common.glsl"

layout(constant_id = 0) const int N = 256;        // VPLs per bounce
layout(constant_id = 1) const int SHADED = 1024;  // IRSM entries per VPL
layout(constant_id = 2) const int WRAP = 1;       // as ism_splat.comp: the subsets wrap
layout(local_size_x = 256) in;
layout(push_constant) uniform Push { int bounce; };  // 1: bounce 2 from bounce 1, ...
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 6, std430) readonly buffer Irsm { vec4 irsm[]; };
layout(set = 0, binding = 7, std430) buffer Cdf { float cdf[]; };  // the cells' sums, then CDF
layout(set = 0, binding = 8, std430) writeonly buffer VplsOut { Vpl vplsOut[]; };

#include "ism_sample.glsl"

const int CELLS_PER_VPL = (SHADED + 255) / 256;

float fluxOf(int e) {
  vec3 f = irsm[e].rgb;
  return f.r + f.g + f.b;
}

void main() {
  int t = int(gl_LocalInvocationID.x);
  int cells = N * CELLS_PER_VPL;
  int chunk = (cells + 255) / 256;
  int begin = min(t * chunk, cells), end = min(begin + chunk, cells);
  float run = 0.0;
  for (int k = begin; k < end; ++k) {
    run += cdf[k];
    cdf[k] = run;
  }
  float sum = ismScan(run, begin, end);
  uint base = uint((bounce - 1) * N);  // the previous bounce's first VPL
  uint perIsm = uint(ism.atlas.z), count = uint(ism.atlas.w);
  for (int i = t; i < N; i += 256) {
    Vpl v;
    v.position = vec4(0.0);
    v.normal = vec4(0.0, 1.0, 0.0, 0.0);
    v.flux = vec4(0.0);
    if (sum > 1e-30 && count > 0u) {
      float target = ismTarget(i, N, sum);
      int k = ismFind(target, cells);
      float rest = target - (k > 0 ? cdf[k - 1] : 0.0);
      int row = k / CELLS_PER_VPL;
      int first = row * SHADED + (k - row * CELLS_PER_VPL) * 256;
      int last = min(first + 256, (row + 1) * SHADED);
      // The entry where the running sum passes the rest (rounding: else the cell's last
      // entry with flux).
      int pick = -1;
      float acc = 0.0;
      for (int e = first; e < last; ++e) {
        float f = fluxOf(e);
        if (!(f > 0.0)) continue;
        pick = e;
        acc += f;
        if (acc > rest) break;
      }
      if (pick >= 0) {
        float p = fluxOf(pick) / sum;
        uint vpl = base + uint(row), j = uint(pick - row * SHADED);
        uint idx = WRAP == 1 ? (vpl * perIsm + j) % count : vpl * perIsm + j;
        vec3 nrm = safeNormalize(points[2u * idx + 1u].xyz, vec3(0.0, 1.0, 0.0));
        v.position = vec4(points[2u * idx].xyz + nrm * (1e-3 * ism.pull.w), 1.0);
        v.normal = vec4(nrm, 0.0);
        v.flux = vec4(irsm[pick].rgb / (p * float(N)), 0.0);
      }
    }
    vplsOut[base + uint(N) + uint(i)] = v;
  }
}
