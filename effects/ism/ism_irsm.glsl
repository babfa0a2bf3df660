// Included by ism_irsm.comp / ism_irsm_classic.comp. Imperfect reflective shadow maps (seed 002
// §4.1): the previous bounce's VPL v renders *shaded points* into its paraboloid. Its points are
// the fixed subset its ISM was splatted from (ism_splat.comp); the first SHADED of them are
// shaded with v's light where v's map says the point is the nearest surface in its texel (the
// depth test, with the gathering's bias: vplIrradiance), i.e. they are the IRSM's filled texels,
// stored per point (a texel no visible point reached holds nothing to sample, so it is not
// stored). Each reflects albedo (base colour; textures ignored) x E x the area it stands for
// (the subset stands for the whole surface). Workgroup: 256 entries of one VPL, a cell of the
// marginal CDF; its sum goes to cells[] for ism_bounce.comp.
#include "common.glsl"
#include "ism_common.glsl"

layout(constant_id = 0) const int SHADED = 1024;  // IRSM entries per VPL (gi::ism::irsmEntries)
layout(constant_id = 1) const int WRAP = 1;       // as ism_splat.comp: the subsets wrap
layout(local_size_x = 256) in;
layout(push_constant) uniform Push { int base; };  // the previous bounce's first VPL
layout(set = 0, binding = 2, std140) uniform Vpls { Vpl vpls[ISM_VPL_SLOTS]; };
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
struct Material {
  vec4 baseColor;
  vec4 emission;
  vec4 params;
};
layout(set = 0, binding = 4, std430) readonly buffer Materials { Material materials[]; };
#include "ism_lookup.glsl"
layout(set = 0, binding = 6, std430) writeonly buffer Irsm { vec4 irsm[]; };  // reflected flux
layout(set = 0, binding = 7, std430) writeonly buffer Cells { float cells[]; };

const int CELLS_PER_VPL = (SHADED + 255) / 256;
shared float cellSum[256];

void main() {
  uint t = gl_LocalInvocationID.x, row = gl_WorkGroupID.y, v = uint(base) + row;
  uint j = gl_GlobalInvocationID.x;
  uint perIsm = uint(ism.atlas.z), count = uint(ism.atlas.w);
  vec3 f = vec3(0.0);
  if (j < uint(SHADED) && count > 0u) {
    Vpl vpl = vpls[v];
    if (vpl.position.w > 0.5) {
      uint idx = WRAP == 1 ? (v * perIsm + j) % count : v * perIsm + j;
      vec4 pa = points[2u * idx], nm = points[2u * idx + 1u];
      vec3 e = vplIrradiance(vpl, v, pa.xyz, nm.xyz);
      vec3 albedo = clamp(materials[int(nm.w)].baseColor.rgb, 0.0, 1.0);
      f = albedo * e * (pa.w * float(count) / float(SHADED));
      float s = f.r + f.g + f.b;
      if (isnan(s) || isinf(s)) f = vec3(0.0);  // guard: a bad point never enters the CDF
    }
    irsm[row * uint(SHADED) + j] = vec4(f, 0.0);
  }
  cellSum[t] = f.r + f.g + f.b;
  barrier();
  for (uint s = 128u; s > 0u; s >>= 1) {
    if (t < s) cellSum[t] += cellSum[t + s];
    barrier();
  }
  if (t == 0u) cells[row * uint(CELLS_PER_VPL) + gl_WorkGroupID.x] = cellSum[0];
}
