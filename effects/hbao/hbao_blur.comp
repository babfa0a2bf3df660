#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Depth-aware (cross-bilateral) blur of the raw HBAO along one axis, the SSAO plugin's blur
// copied (effects do not depend on each other); the blur pass runs it along x, then along y.
// Spatial weights: a box of width 2 radius with half-weight ends ([.5 1 1 1 .5] for radius 2):
// for even radii every phase of the 4x4 interleave gets the same weight, so the pattern cancels
// exactly on flat regions. Edge stopping: a neighbour gets no weight when its view distance
// differs by more than the tolerance from the centre's tangent plane extended to it (1/z of a
// plane is affine in screen space, so the prediction is exact along a plane at any angle).
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int kRadius = 2;  // >= 1 (radius 0 has no blur pass)

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D gDepth;
layout(set = 0, binding = 2) uniform sampler2D gNormal;
layout(set = 0, binding = 3) uniform sampler2D inAO;
layout(set = 0, binding = 4, r16f) uniform writeonly image2D outAO;
layout(push_constant) uniform Axis {
  ivec2 axis;       // (1, 0) or (0, 1)
  float tolerance;  // world units
} pc;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;

  float depth = texelFetch(gDepth, p, 0).r;
  mat4 proj = frame.proj;
  // Guards: a degenerate projection must not divide by zero.
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float invP32 = 1.0 / p32, p22 = proj[2][2];
  float ic = (depth + p22) * invP32;  // 1 / view distance

  // Tangent-plane slope along the axis: d(1/z)/dpixel = (1/z) (N.x dDx, N.y dDy) / (N.D).
  vec3 n = texelFetch(gNormal, p, 0).xyz;
  vec2 ndc = (vec2(p) + 0.5) * 2.0 * frame.viewport.zw - 1.0;
  vec3 D = vec3((ndc.x + proj[2][0]) / p00, (ndc.y + proj[2][1]) / p11, -1.0);
  float nd = dot(n, D);
  vec2 dD = 2.0 * frame.viewport.zw / vec2(p00, p11);
  // Guard: a grazing or zero normal (N.D near 0) predicts nothing: slope 0.
  float slope = nd < -1e-4 * length(D) * length(n) ? ic * dot(n.xy * dD, vec2(pc.axis)) / nd : 0.0;

  float tol = pc.tolerance;
  float sum = texelFetch(inAO, p, 0).r, weights = 1.0;
  for (int o = -kRadius; o <= kRadius; ++o) {
    if (o == 0) continue;
    ivec2 q = p + o * pc.axis;
    bool inside = q.x >= 0 && q.y >= 0 && q.x < size.x && q.y < size.y;
    q = clamp(q, ivec2(0), size - 1);
    float iq = (texelFetch(gDepth, q, 0).r + p22) * invP32;  // sky: 1 / far, rejected below
    float pred = ic + slope * float(o);
    // |1/iq - 1/pred| < tol, without a division (iq, pred > 0).
    bool sameSurface = inside && pred > 0.0 && abs(pred - iq) < tol * iq * pred;
    float w = sameSurface ? (abs(o) == kRadius ? 0.5 : 1.0) : 0.0;
    sum += w * texelFetch(inAO, q, 0).r;
    weights += w;
  }
  // Guard: sky / far-plane pixels stay open; weights >= 1 (the centre always counts).
  imageStore(outAO, p, vec4(isSky(depth) ? 1.0 : sum / weights));
}
