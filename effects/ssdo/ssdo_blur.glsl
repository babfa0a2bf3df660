// Geometry-aware (cross-bilateral) blur of the raw SSDO terms along one axis, included by
// ssdo_blur_x.comp (writes the packed texel again) and ssdo_resolve.comp (y axis, then x
// diffuse albedo: writes `ambient` and `indirect`). One fetch per tap: the raw texel carries
// both terms, 1 / view distance and the normal (ssdo_common.glsl).
// Weights: a box of width 2 radius with half-weight ends, so for even radii every phase of the
// 4x4 sample-set pattern gets the same weight and the pattern cancels on flat regions (as in
// effects/ssao). Edge stopping: a neighbour gets weight 0 when it lies farther than the
// tolerance from the centre's tangent plane (depth discontinuities, creases) or its normal
// differs by more than acos(min cosine) (normal discontinuities).
//
// Include after defining GI_BLUR_AXIS (0: x, 1: y) and declaring the outputs.
layout(local_size_x = 32, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
#include "ssdo_common.glsl"
layout(set = 0, binding = 2) uniform usampler2D inRaw;
layout(constant_id = 0) const int kRadius = 2;  // 0..gi::ssdo::kMaxBlurRadius: the loop unrolls

// The blurred terms of pixel p; `centre` is its raw texel.
void ssdoBlur(ivec2 p, ivec2 size, uvec4 centre, out vec3 direct, out vec3 bounce) {
  const ivec2 axis = GI_BLUR_AXIS == 0 ? ivec2(1, 0) : ivec2(0, 1);
  mat4 proj = frame.proj;
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p20 = proj[2][0], p21 = proj[2][1];
  vec2 invSize = frame.viewport.zw;
  float ic = uintBitsToFloat(centre.z);
  vec3 P = ssdoViewPosition(vec2(p) + 0.5, max(ic, 1e-30), invSize, p00, p11, p20, p21);
  vec3 N = unpackNormal(centre.w);
  float tol = ssdo.blur.x, minCos = ssdo.blur.y;
  direct = unpackRgb9e5(centre.x);
  bounce = unpackRgb9e5(centre.y);
  float weights = 1.0;
  for (int o = -kRadius; o <= kRadius; ++o) {
    if (o == 0) continue;
    ivec2 q = p + o * axis;
    bool inside = q.x >= 0 && q.y >= 0 && q.x < size.x && q.y < size.y;
    uvec4 t = texelFetch(inRaw, clamp(q, ivec2(0), size - 1), 0);
    float iq = uintBitsToFloat(t.z);  // sky: 0, rejected
    vec3 Q = ssdoViewPosition(vec2(q) + 0.5, max(iq, 1e-30), invSize, p00, p11, p20, p21);
    bool same = inside && ic > 0.0 && iq > 0.0 && abs(dot(N, Q - P)) < tol &&
                dot(N, unpackNormal(t.w)) > minCos;
    float w = same ? (abs(o) == kRadius ? 0.5 : 1.0) : 0.0;
    direct += w * unpackRgb9e5(t.x);
    bounce += w * unpackRgb9e5(t.y);
    weights += w;
  }
  direct /= weights;  // weights >= 1: the centre always counts
  bounce /= weights;
}
