#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "depth_aware_blur.glsl"

// Screen-space ambient occlusion (RTR 11.3.6, seed 001 §4.2-4.3). The estimator, kernel
// distribution and interleaving are described in ssao_kernel.h. Reads the reverse-Z depth and
// the view-space normal; writes per pixel AO (1 = open) packed for the engine's depth-aware
// blur (depth_aware_blur.glsl: with 1 / view distance and the tangent plane's slopes).
//
// Assumes a perspective projection (clip.w = view distance), as every engine camera has.
layout(local_size_x = 32, local_size_y = 16) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Keep in sync with gi::ssao::Uniforms (ssao_kernel.h).
layout(set = 0, binding = 1) uniform SsaoParams {
  vec4 params;   // radius, bias (world), intensity, 0
  ivec4 counts;  // samples, 0, 0, 0
  vec4 rotation[16];
  uvec4 kernel[16];  // tap i: kernel[i / 4][i % 4], 11/11/10 bits (gi::ssao::packTap)
} ssao;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"  // the packed G-buffer
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D outAO;  // ao, 1/z, slopes

// Guard: taps at or behind the camera plane (clip.w below this) are untestable: open.
const float kMinClipW = 1e-20;
// Guard: the depth buffer gives view distances to a relative ~2^-23 only (float32 reverse-Z),
// and the slide below rounds too: an occluder must lie at least this fraction of its distance
// in front of a tap, or a flat face occludes itself in bands once the radius (and so the bias)
// nears that resolution. Radii below it find no occluders at all (AO 1: unresolvable).
const float kDepthResolution = 1e-6;
// Guard: the texel-centre slide (below) is skipped when the tap's tangent-parallel plane passes
// this close to the camera (|N.Q| below kSlideMinK x view distance): it would be ill-conditioned.
const float kSlideMinK = 1e-4;

// Clip coordinates of view-space v (a point or, linear in v, an offset) with x and y already
// mapped to pixels: (x + w) / 2 * size, and w = -v.z (pixel = xy / w).
vec3 clipToPixels(vec3 v, float p00, float p11, float p20, float p21, vec2 halfSize) {
  float w = -v.z;
  return vec3((vec2(p00 * v.x + p20 * v.z, p11 * v.y + p21 * v.z) + w) * halfSize, w);
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;

  float depth = texelFetch(gDepth, p, 0).r;
  uvec4 gTexel = giGBufferLoad(p);
  // Guard: sky / far-plane pixels (depth 0) and pixels without geometry are open; no taps.
  if (isSky(depth) || !giGBufferIsGeometry(gTexel)) {
    imageStore(outAO, p, depthAwareBlurPack(frame, 1.0, vec3(0.0), vec3(0.0, 0.0, 1.0)));
    return;
  }

  // The projection's non-zero terms (perspective: clip.w = -z): the full mat4 products cost
  // llvmpipe 16 multiply-adds each, these 2-3.
  mat4 proj = frame.proj;
  // Guards: a degenerate projection must not divide by zero.
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  float p20 = proj[2][0], p21 = proj[2][1], p22 = proj[2][2];
  // Reverse-Z depth to view distance: 1/z = (d + P22) / P32 (affine in d), then x, y from NDC.
  vec2 ndc = (vec2(p) + 0.5) * 2.0 * frame.viewport.zw - 1.0;
  float dist = p32 / max(depth + p22, 1e-30);
  vec3 P = vec3((ndc.x + p20) * dist / p00, (ndc.y + p21) * dist / p11, -dist);
  // Guard: a zero or NaN normal falls back to facing the camera.
  vec3 N = safeNormalize(giGBufferNormal(gTexel), safeNormalize(-P, vec3(0.0, 0.0, 1.0)));

  // Tangent frame without a helper axis (Duff et al. 2017, "Building an orthonormal basis,
  // revisited"): |s + N.z| >= 1, so it never degenerates, whatever the normal's direction.
  float s = N.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + N.z);
  float b = N.x * N.y * a;
  vec3 T = vec3(1.0 + s * N.x * N.x * a, s * b, -s * N.x);
  vec3 B = vec3(b, s + N.y * N.y * a, -N.y);
  vec2 rot = ssao.rotation[(p.y & 3) * 4 + (p.x & 3)].xy;  // interleave: 16 rotations
  vec3 Tr = rot.x * T + rot.y * B;
  vec3 Br = rot.x * B - rot.y * T;

  // Taps are projected incrementally: clip(Q) = clip(P) + x clip(R T') + y clip(R B') + z clip(R N),
  // keeping only x, y and w (the view distance), with x and y already mapped to pixels:
  // pixel = (x + w) / w * size / 2.
  float R = ssao.params.x;
  vec2 halfSize = 0.5 * vec2(size);
  vec3 clipP = clipToPixels(P, p00, p11, p20, p21, halfSize),
       clipT = clipToPixels(R * Tr, p00, p11, p20, p21, halfSize),
       clipB = clipToPixels(R * Br, p00, p11, p20, p21, halfSize),
       clipN = clipToPixels(R * N, p00, p11, p20, p21, halfSize);
  float invP32 = 1.0 / p32;

  // Texel-centre slide: the depth buffer is read at the centre of the texel a tap falls in, so
  // the tap is moved, parallel to the tangent plane, onto that centre's view ray before the
  // comparison. A flat surface then never occludes itself at any viewing angle (a half-texel
  // offset along a grazing plane is otherwise a large depth error). On the plane N.X = K the
  // inverse distance is affine in NDC: 1/z(ndc') = 1/z(ndc) + (g . (ndc' - ndc)) / K with
  // g = (N.x / P00, N.y / P11); here in pixel units (g scaled by 2 / size).
  vec2 g = vec2(N.x / p00, N.y / p11) * 2.0 * frame.viewport.zw;
  float NP = dot(N, P);
  float minK = -kSlideMinK * max(-P.z, 1e-20);  // strictly negative: min(K, minK) != 0

  vec2 sizeF = vec2(size);
  float bias = ssao.params.y;
  int count = clamp(ssao.counts.x, 1, 64);
  float occluded = 0.0;
  for (int i = 0; i < count; ++i) {
    uint code = ssao.kernel[i >> 2][i & 3];
    vec3 k = vec3(float(code & 2047u) * (2.0 / 2047.0) - 1.0,
                  float((code >> 11) & 2047u) * (2.0 / 2047.0) - 1.0,
                  float(code >> 22) * (1.0 / 1023.0));
    vec3 c = clipP + clipT * k.x + clipB * k.y + clipN * k.z;
    // One division for both reciprocals the tap needs, 1 / w and 1 / K (K = N . Q, the rotation
    // about N leaves it unchanged; clamped to <= minK < 0, so the product never vanishes).
    float K = NP + R * k.z;
    float Kc = min(K, minK), w = max(c.z, kMinClipW);
    float r = 1.0 / (w * Kc);
    float invW = r * Kc, invK = r * w;
    vec2 pix = c.xy * invW;
    // Guard: taps behind the camera or off screen count as unoccluded.
    bool valid = c.z > kMinClipW && pix.x >= 0.0 && pix.y >= 0.0 && pix.x < sizeF.x &&
                 pix.y < sizeF.y;
    ivec2 t = ivec2(clamp(pix, vec2(0.0), sizeF - 1.0));
    float iS = (texelFetch(gDepth, t, 0).r + p22) * invP32;  // stored surface, 1 / distance

    float slid = invW + dot(g, vec2(t) + 0.5 - pix) * invK;
    float iQ = (K < minK && slid > 0.0) ? slid : invW;  // tap, 1 / distance

    // max(bias, resolution x zQ) < zQ - zS < R, in inverse distances (both positive; zQ x iS x
    // iQ = iS): no division needed.
    float diff = iS - iQ, prod = iS * iQ;
    occluded += (valid && diff > max(bias * prod, kDepthResolution * iS) && diff < R * prod)
                    ? 1.0
                    : 0.0;
  }
  float ao = clamp(1.0 - ssao.params.z * occluded / float(count), 0.0, 1.0);
  imageStore(outAO, p, depthAwareBlurPack(frame, ao, P, N));
}
