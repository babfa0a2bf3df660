// Geometry-aware (cross-bilateral) blur of the raw SSDO terms along one axis, included by
// ssdo_blur_x.comp (writes the packed texel again) and ssdo_resolve.comp (y axis, then x
// diffuse albedo: writes `ambient` and `indirect`). One fetch per tap: the raw texel carries
// both terms, 1 / view distance and the normal (ssdo_common.glsl).
// Weights: a box of width 2 radius with half-weight ends, so for even radii every phase of the
// 4x4 sample-set pattern gets the same weight and the pattern cancels on flat regions (as in
// effects/ssao). Edge stopping: a neighbour gets weight 0 when its view distance differs by
// more than the tolerance from the centre's tangent plane extended to it (depth
// discontinuities, and creases once they leave the plane) or, with `blur_normals`, its normal
// differs by more than acos(min cosine) (creases from their first pixel on).
//
// Include after defining GI_BLUR_AXIS (0: x, 1: y) and declaring the outputs.
layout(local_size_x = 32, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
#include "ssdo_common.glsl"
#include "depth_aware_blur.glsl"  // depthAwareBlurWeight
layout(set = 0, binding = 2) uniform usampler2D inRaw;
layout(constant_id = 0) const int kRadius = 2;  // 0..gi::ssdo::kMaxBlurRadius: the loop unrolls
// The bounce term (off: `bounce` is 0, never decoded: the blur then costs what one term does).
layout(constant_id = 1) const bool kBounceTerm = true;
// The normal test (`blur_normals`; off: the plane test alone, as the engine's blur).
layout(constant_id = 2) const bool kNormalTest = true;

// The blurred terms of pixel p; `centre` is its raw texel.
void ssdoBlur(ivec2 p, ivec2 size, uvec4 centre, out vec3 direct, out vec3 bounce) {
  const ivec2 axis = GI_BLUR_AXIS == 0 ? ivec2(1, 0) : ivec2(0, 1);
  mat4 proj = frame.proj;
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p20 = proj[2][0], p21 = proj[2][1];
  vec2 invSize = frame.viewport.zw;
  float ic = uintBitsToFloat(centre.z);
  vec3 N = safeNormalize(unpackBlurNormal(centre.w), vec3(0.0, 0.0, 1.0));
  // The centre's tangent plane predicts 1/z along the axis: 1/z is affine in screen space on a
  // plane, d(1/z)/dpixel = (1/z) N.xy dD / (N.D) for the view ray D (z = -1) (effects/ssao).
  // Guard: a grazing plane (N.D near 0) predicts a constant.
  vec2 ndc = (vec2(p) + 0.5) * 2.0 * invSize - 1.0;
  vec3 D = vec3((ndc.x + p20) / p00, (ndc.y + p21) / p11, -1.0);
  float nd = dot(N, D);
  vec2 dD = 2.0 * invSize / vec2(p00, p11);
  vec2 slopes = nd < -1e-4 * length(D) ? ic * N.xy * dD / nd : vec2(0.0);
  float slope = GI_BLUR_AXIS == 0 ? slopes.x : slopes.y;
  float tol = ssdo.blurTolerance, minCos2 = ssdo.blurMinCos * ssdo.blurMinCos;
  direct = unpackRgb9e5(centre.x);
  bounce = kBounceTerm ? unpackRgb9e5(centre.y) : vec3(0.0);
  float weights = 1.0;
  for (int o = -kRadius; o <= kRadius; ++o) {
    if (o == 0) continue;
    bool inside;
    uvec4 t = texelFetch(inRaw, depthAwareBlurTap(p, o, axis, size, inside), 0);
    // The normals within acos(min cosine), without normalizing the neighbour's:
    // (N.n)^2 > c^2 |n|^2.
    bool sameNormal = true;
    if (kNormalTest) {
      vec3 n = unpackBlurNormal(t.w);
      float c = dot(N, n);
      sameNormal = c > 0.0 && c * c > minCos2 * dot(n, n);
    }
    float iq = uintBitsToFloat(t.z);  // sky: 0, no weight
    float w = inside && sameNormal ? depthAwareBlurWeight(o, kRadius, ic, slope, iq, tol) : 0.0;
    direct += w * unpackRgb9e5(t.x);
    if (kBounceTerm) bounce += w * unpackRgb9e5(t.y);
    weights += w;
  }
  direct /= weights;  // weights >= 1: the centre always counts
  bounce /= weights;
}
