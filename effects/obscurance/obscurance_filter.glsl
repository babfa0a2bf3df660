// Depth-aware 4x4 box filter of the per-pixel sums (seed 001 §4.2), one axis per dispatch:
// obscurance_filter.comp runs it along x (sums -> sums), obscurance_resolve.comp along y and
// divides (sums -> "ao"). Included by both with GI_AXIS and GI_RESOLVE defined.
//
// Weights [.5 1 1 1 .5]: every phase of the 4x4 interleave gets the same weight along each axis
// (a 4-wide box, centred), so the pattern cancels on flat regions. A neighbour is skipped when
// its view distance differs by more than the tolerance (a fraction of R) from the centre's
// tangent plane extended to it (exact along planes at any angle; rejects depth edges and
// creases), as in ssao_blur.comp. Sums are filtered before dividing: W = sum N / sum D is the
// weighted-importance-sampling ratio over all 16 rotations.
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int MODE = 0;    // 0 obscurance, 1 W (albedo), 2 W (emission)
layout(constant_id = 1) const int RADIUS = 2;  // 2: the 4x4 box; 0: no filtering (resolve only)

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform ObscuranceParams {
  vec4 params;  // radius, bias (world), filter depth tolerance (world), transfer guard
  vec4 rotation[16];
  uvec4 kernel[16];
} obs;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
layout(set = 0, binding = 3) uniform sampler2D gNormal;
layout(set = 0, binding = 4) uniform sampler2D inSums;
#if GI_RESOLVE
layout(set = 0, binding = 5, r16f) uniform writeonly image2D outImage;
#else
layout(set = 0, binding = 5, rg16f) uniform writeonly image2D outImage;
#endif

vec4 finish(vec2 sums) {
#if GI_RESOLVE
  if (MODE == 0) return vec4(sums.x);
  // Guarded transfer ratio (obscurance_kernel.h: the phantom open sample): finite, in [0, 1]
  // for albedo in [0, 1] since N <= D, and 1 when every ray is closed by white occluders.
  float eta = obs.params.w;
  float w = (sums.x + eta) / (sums.y + eta);
  return vec4(MODE == 2 ? clamp(w, 0.0, 1.0) : w);
#else
  return vec4(sums, 0.0, 0.0);
#endif
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  const ivec2 axis = GI_AXIS;

  vec2 centre = texelFetch(inSums, p, 0).rg;
  if (RADIUS == 0) {  // folded at specialization: resolve only
    imageStore(outImage, p, finish(centre));
    return;
  }
  float depth = texelFetch(gDepth, p, 0).r;
  if (isSky(depth)) {  // guard: sky stays open
    imageStore(outImage, p, finish(vec2(1.0)));
    return;
  }
  mat4 proj = frame.proj;
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float invP32 = 1.0 / p32, p22 = proj[2][2];
  float ic = (depth + p22) * invP32;  // 1 / view distance

  // Tangent-plane slope of 1/z along the axis (see ssao_blur.comp).
  vec3 n = texelFetch(gNormal, p, 0).xyz;
  vec2 ndc = (vec2(p) + 0.5) * 2.0 * frame.viewport.zw - 1.0;
  vec3 D = vec3((ndc.x + proj[2][0]) / p00, (ndc.y + proj[2][1]) / p11, -1.0);
  float nd = dot(n, D);
  vec2 dD = 2.0 * frame.viewport.zw / vec2(p00, p11);
  // Guard: a grazing or zero normal predicts nothing (slope 0).
  float slope = nd < -1e-4 * length(D) * length(n) ? ic * dot(n.xy * dD, vec2(axis)) / nd : 0.0;

  float tol = obs.params.z;
  vec2 sum = centre;
  float weights = 1.0;
  for (int o = -RADIUS; o <= RADIUS; ++o) {
    if (o == 0) continue;
    ivec2 q = p + o * axis;
    bool inside = q.x >= 0 && q.y >= 0 && q.x < size.x && q.y < size.y;
    q = clamp(q, ivec2(0), size - 1);
    float iq = (texelFetch(gDepth, q, 0).r + p22) * invP32;  // sky: rejected below
    float pred = ic + slope * float(o);
    bool sameSurface = inside && pred > 0.0 && abs(pred - iq) < tol * iq * pred;
    float w = sameSurface ? (abs(o) == RADIUS ? 0.5 : 1.0) : 0.0;
    sum += w * texelFetch(inSums, q, 0).rg;
    weights += w;
  }
  imageStore(outImage, p, finish(sum / weights));  // weights >= 1: the centre always counts
}
