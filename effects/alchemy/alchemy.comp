#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "guards.glsl"

// Alchemy ambient obscurance (McGuire et al. 2011, seed 003 eq. 10). The estimator, its guards
// and the tap pattern are described in alchemy_kernel.h (gi::alchemy::estimate is this shader
// on the CPU). Reads reverse-Z depth and view-space normals of the view `frame` describes (the
// main view, or the guard-band view: the same camera with kBand more pixels on each side) and
// writes, per output pixel p (input pixel p + kBand), RGBA32F:
//   (AO, 1 / view distance, d(1/z)/dx, d(1/z)/dy of the tangent plane)
// so that the cross-bilateral blur reads one texel per tap (sky: (1, 0, 0, 0)).
//
// Assumes a perspective projection (clip.w = view distance), as every engine camera has.
layout(local_size_x = 32, local_size_y = 16) in;

// Specialized at pipeline creation (vk::Pipeline::compute): a constant trip count and the band
// offset folded into the addressing.
layout(constant_id = 0) const int kSamples = 12;
layout(constant_id = 1) const int kBand = 0;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Keep in sync with gi::alchemy::Uniforms (alchemy_kernel.h).
layout(set = 0, binding = 1) uniform AlchemyParams {
  float radius;         // r, world units
  float bias;           // beta
  float scale;          // 2 sigma / s
  float contrast;       // k
  float epsilon;        // denominator guard
  float blurTolerance;  // absolute, world units
  float radius2;        // r^2
  float pad;
  uvec4 taps[16];  // tap i: taps[i / 4][i % 4], packSnorm2x16 of its unit-disk offset
} params;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"  // the packed G-buffer
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D outAO;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 outSize = imageSize(outAO);
  if (p.x >= outSize.x || p.y >= outSize.y) return;
  ivec2 q = p + kBand;  // the input pixel
  ivec2 size = ivec2(frame.viewport.xy);

  float depth = texelFetch(gDepth, q, 0).r;
  uvec4 gTexel = giGBufferLoad(q);

  mat4 proj = frame.proj;
  // Guards: a degenerate projection must not divide by zero.
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  float p20 = proj[2][0], p21 = proj[2][1], p22 = proj[2][2];
  // Reverse-Z depth to view distance: 1/z = (d + P22) / P32 (affine in d).
  float invP32 = 1.0 / p32;
  vec2 toNdc = 2.0 * frame.viewport.zw;
  vec2 ndc = (vec2(q) + 0.5) * toNdc - 1.0;
  float ic = (depth + p22) * invP32;
  float dist = 1.0 / max(ic, 1e-30);
  vec3 C = vec3((ndc.x + p20) * dist / p00, (ndc.y + p21) * dist / p11, -dist);
  // Guard: a zero or NaN normal falls back to facing the camera.
  vec3 N = safeNormalize(giGBufferNormal(gTexel), safeNormalize(-C, vec3(0.0, 0.0, 1.0)));

  // Projected radius in pixels; guard: clamped to the image size (a camera inside the ball
  // would otherwise send taps to integer overflow).
  float r = params.radius, beta = params.bias, eps = params.epsilon, r2 = params.radius2;
  float rpx = min(r * abs(p11) * 0.5 * float(size.y) / dist, float(max(size.x, size.y)));
  // 4x4 interleave: Bayer rank of the output pixel (gi::alchemy::bayerRank), 16 rotations.
  int bx = (p.x ^ p.y) & 3;
  int j = ((bx & 1) << 3) | ((p.y & 1) << 2) | ((bx >> 1) << 1) | ((p.y >> 1) & 1);
  float phi = float(j) * (2.0 * 3.14159265 / 16.0);
  vec2 rot = vec2(cos(phi), sin(phi)) * rpx;

  vec2 centre = vec2(q) + 0.5;
  float biasZ = beta * dist;
  // The view ray (z = -1) through a texel's centre is affine in the texel: D(t) = ray0 + t dRay.
  vec2 invP = 1.0 / vec2(p00, p11);
  vec2 dRay = toNdc * invP;
  vec2 ray0 = (0.5 * toNdc - 1.0 + vec2(p20, p21)) * invP;
  float sum = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    vec2 o = unpackSnorm2x16(params.taps[i >> 2][i & 3]);  // the spiral tap on the unit disk
    vec2 tp = floor(centre + vec2(o.x * rot.x - o.y * rot.y, o.x * rot.y + o.y * rot.x));
    // Guard: taps outside the depth image count as unoccluded (clamped for the fetch).
    bool inside = tp.x >= 0.0 && tp.y >= 0.0 && tp.x < float(size.x) && tp.y < float(size.y);
    vec2 t = clamp(tp, vec2(0.0), vec2(size - 1));
    float d = texelFetch(gDepth, ivec2(t), 0).r;
    // With it = 1 / (the tap's view distance) and P = D / it: w = it v = D - it C, so
    //   max(0, v.n - beta z) / (v.v + epsilon) = it max(0, w.n - beta z it) / (w.w + epsilon it^2)
    // and v.v < r^2 <=> w.w < r^2 it^2: one division per tap instead of three.
    float it = (d + p22) * invP32;
    vec3 w = vec3(ray0 + t * dRay, -1.0) - it * C;
    float ww = dot(w, w), it2 = it * it;
    // epsilon: the denominator's guard (v = 0 gives 0 / epsilon; a tap adds at most
    // 1 / (2 sqrt(epsilon))). Sky taps and taps beyond r (eq. 9's Heaviside) count nothing.
    float term = it * max(0.0, dot(w, N) - biasZ * it) / (ww + eps * it2);
    sum += (inside && !isSky(d) && ww < r2 * it2) ? term : 0.0;
    // The epsilon counted where it dominates the denominator of a counted tap (v.v < epsilon).
    giGuard(GI_GUARD_DENOMINATOR, inside && !isSky(d) && ww < eps * it2 && term > 0.0);
  }
  float base = max(0.0, 1.0 - params.scale * sum);
  float ao = base > 0.0 ? min(pow(base, params.contrast), 1.0) : 0.0;  // NaN sum: 0, never NaN

  // Tangent-plane slopes of 1/z per pixel for the blur's edge stopping: on the plane N.X = K,
  // 1/z = (N.D)/K with D the pixel's view ray (z = -1), so d(1/z)/dpixel = (1/z) N.xy dRay / (N.D).
  vec3 D = vec3((ndc + vec2(p20, p21)) * invP, -1.0);
  float nd = dot(N, D);
  // Guard: a grazing plane (N.D near 0) predicts nothing: slope 0.
  vec2 slope = nd < -1e-4 * length(D) ? ic * N.xy * dRay / nd : vec2(0.0);

  bool sky = isSky(depth) || !giGBufferIsGeometry(gTexel);
  imageStore(outAO, p, sky ? vec4(1.0, 0.0, 0.0, 0.0) : vec4(ao, ic, slope));
}
