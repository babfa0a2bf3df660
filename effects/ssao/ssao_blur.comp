#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Depth-aware (cross-bilateral) blur of the raw SSAO, separable, in one pass: a 16x16 tile plus
// an apron of `radius` texels is loaded into shared memory, blurred along x, then along y.
//
// Spatial weights: a box of width 2 radius with half-weight ends ([.5 1 1 1 .5] for radius 2),
// which for even radii gives every phase of the 4x4 interleave pattern the same weight, so the
// pattern cancels exactly on flat regions.
// Edge stopping: a neighbour gets zero weight when its view distance differs by more than the
// tolerance (a fraction of the AO radius) from the centre's tangent plane extended to it. The
// plane comes from the centre's G-buffer normal; 1/z of a plane is affine in screen space, so
// the prediction is exact along a plane at any angle, and a surface across a depth
// discontinuity (or a crease) is rejected.
layout(local_size_x = 16, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Keep in sync with gi::ssao::Uniforms (ssao_kernel.h).
layout(set = 0, binding = 1) uniform SsaoParams {
  vec4 params;   // radius, bias (world), intensity, blur depth tolerance (world)
  ivec4 counts;  // samples, blur radius
  vec4 rotation[16];
  vec4 kernel[64];
} ssao;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
layout(set = 0, binding = 3) uniform sampler2D gNormal;
layout(set = 0, binding = 4) uniform sampler2D rawAO;
layout(set = 0, binding = 5, r16f) uniform writeonly image2D outAO;

const int kTile = 16;
const int kMaxRadius = 8;  // gi::ssao::kMaxBlurRadius
const int kSpan = kTile + 2 * kMaxRadius;
shared float sAO[kSpan * kSpan];
shared float sInv[kSpan * kSpan];  // 1 / view distance; -1 outside the image or sky
shared float sH[kSpan * kTile];    // AO blurred along x, at the tile's columns
shared vec2 sSlope[kSpan * kTile]; // d(1/z)/dpixel of the tangent plane, relative to 1/z

// Zero outside the tolerance; inverse distances (iq, pred > 0) avoid a division:
// |1/iq - 1/pred| < tol  <=>  |pred - iq| < tol * iq * pred.
float depthWeight(float iq, float pred, float tol) {
  return (iq > 0.0 && pred > 0.0 && abs(pred - iq) < tol * iq * pred) ? 1.0 : 0.0;
}

float spatialWeight(int o, int r) { return abs(o) == r ? 0.5 : 1.0; }

void main() {
  ivec2 size = ivec2(frame.viewport.xy);
  ivec2 l = ivec2(gl_LocalInvocationID.xy);
  int r = clamp(ssao.counts.y, 1, kMaxRadius);
  int span = kTile + 2 * r;
  ivec2 origin = ivec2(gl_WorkGroupID.xy) * kTile - r;
  mat4 proj = frame.proj;
  // Guards: a degenerate projection must not divide by zero.
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float invP32 = 1.0 / p32, p22 = proj[2][2];
  float tol = ssao.params.w;

  // 1. The tile and its apron: AO and inverse distance.
  for (int y = l.y; y < span; y += kTile) {
    for (int x = l.x; x < span; x += kTile) {
      ivec2 q = origin + ivec2(x, y);
      bool inside = q.x >= 0 && q.y >= 0 && q.x < size.x && q.y < size.y;
      ivec2 qc = clamp(q, ivec2(0), size - 1);
      float d = texelFetch(gDepth, qc, 0).r;
      sAO[y * span + x] = texelFetch(rawAO, qc, 0).r;
      sInv[y * span + x] = (inside && !isSky(d)) ? (d + p22) * invP32 : -1.0;
    }
  }
  // Tangent-plane slopes at the centres of the x pass (every row, the tile's columns): on the
  // plane N.X = K through the pixel, 1/z = (N . D) / K with D = the pixel's view ray (z = -1),
  // so d(1/z)/dpixel = (1/z) (N.x dDx, N.y dDy) / (N . D).
  vec2 dD = 2.0 * frame.viewport.zw / vec2(p00, p11);
  for (int y = l.y; y < span; y += kTile) {
    ivec2 q = clamp(origin + ivec2(r + l.x, y), ivec2(0), size - 1);
    vec3 n = texelFetch(gNormal, q, 0).xyz;
    vec2 ndc = (vec2(q) + 0.5) * 2.0 * frame.viewport.zw - 1.0;
    vec3 D = vec3((ndc.x + proj[2][0]) / p00, (ndc.y + proj[2][1]) / p11, -1.0);
    float nd = dot(n, D);
    // Guard: a grazing or zero normal (N . D near 0) predicts nothing: slope 0, so only
    // neighbours at the centre's own distance are averaged.
    sSlope[y * kTile + l.x] = nd < -1e-4 * length(D) * length(n) ? n.xy * dD / nd : vec2(0.0);
  }
  barrier();

  // 2. Along x, for every row of the apron.
  for (int y = l.y; y < span; y += kTile) {
    int c = y * span + r + l.x;
    float ic = sInv[c];
    float result = sAO[c];
    if (ic > 0.0) {
      float slope = sSlope[y * kTile + l.x].x * ic;
      float sum = 0.0, weights = 0.0;
      for (int o = -r; o <= r; ++o) {
        float w = spatialWeight(o, r) *
                  (o == 0 ? 1.0 : depthWeight(sInv[c + o], ic + slope * float(o), tol));
        sum += w * sAO[c + o];
        weights += w;
      }
      result = sum / max(weights, 1e-6);  // guard: the centre always weighs 1 anyway
    }
    sH[y * kTile + l.x] = result;
  }
  barrier();

  // 3. Along y, for this invocation's pixel.
  ivec2 p = ivec2(gl_WorkGroupID.xy) * kTile + l;
  if (p.x >= size.x || p.y >= size.y) return;
  int y0 = l.y + r;
  int c = y0 * span + r + l.x;
  float ic = sInv[c];
  float ao = 1.0;  // guard: sky / far plane stays open
  if (ic > 0.0) {
    float slope = sSlope[y0 * kTile + l.x].y * ic;
    float sum = 0.0, weights = 0.0;
    for (int o = -r; o <= r; ++o) {
      float w = spatialWeight(o, r) *
                (o == 0 ? 1.0 : depthWeight(sInv[c + o * span], ic + slope * float(o), tol));
      sum += w * sH[(y0 + o) * kTile + l.x];
      weights += w;
    }
    ao = sum / max(weights, 1e-6);
  }
  imageStore(outAO, p, vec4(ao));
}
