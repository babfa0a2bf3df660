#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Obscurance / ambient transfer (seed 001 §4, eqs. 7-9): containment tests of precomputed
// samples (cosine x mu' importance sampled, obscurance_kernel.h) against the depth buffer, with
// the silhouette test 0 < z - z* < R and 4x4 interleaved rotations. Writes per pixel the sample
// means of the numerator and denominator of eq. 9 (N / n, D / n) and what the depth-aware
// filter needs of the G-buffer (1 / view distance and its tangent-plane slopes), packed in one
// RGBA32UI texel so that the filter fetches each neighbour once (notes/llvmpipe.md: ~1 ms per
// full-screen fetch at 640x480); the filter averages the sums over 4x4 pixels and divides.
// MODE 3 (transfer = radiance) sums colours instead: the ambient radiance per unit albedo,
// A = (L^a O + (1/pi) Int (1 - mu) L_d(y) cos) / (1 - (1/pi) Int (1 - mu) a(y) cos), with
// L_d the occluders' direct radiance (obscurance_radiance.comp) and L^a the environment's
// E(n) / pi at the pixel, RGB: colour bleeding from lit neighbours, and A may exceed L^a.
// Settings that change code are specialization constants (notes/llvmpipe.md: a runtime `if`
// runs both sides on llvmpipe; constant loops unroll, so the UBO taps are scalar loads).
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int SAMPLES = 16;  // rays per pixel, 1..64
layout(constant_id = 1) const int POINTS = 1;    // test points per ray (1 or 2)
// 0 obscurance, 1 W with albedo, 2 W with emission, 3 ambient radiance A (RGB, see above)
layout(constant_id = 2) const int MODE = 0;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Keep in sync with gi::obscurance::Uniforms (obscurance_kernel.h).
layout(set = 0, binding = 1) uniform ObscuranceParams {
  float radius;           // R, world units
  float bias;             // absolute, world units
  float filterTolerance;  // absolute, world units
  float guard;            // the transfer's denominator guard
  vec4 rotation[16];
  uvec4 kernel[16];  // tap i: kernel[i / 4][i % 4], 11/11/10 bits (packTap)
} obs;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"  // the packed G-buffer: normal, the occluders' albedo and emission
layout(set = 0, binding = 5) uniform sampler2D gRadiance;  // MODE 3: the occluders' L_d
layout(set = 0, binding = 6, rgba32ui) uniform writeonly uimage2D outSums;

// Guard: test points at or behind the camera plane (clip.w below this) are untestable: open.
const float kMinClipW = 1e-20;
// Guard: the texel-centre slide is skipped when the point's tangent-parallel plane passes this
// close to the camera (|N.Q| below kSlideMinK x view distance): it would be ill-conditioned.
const float kSlideMinK = 1e-4;
// Emission mode: an occluder's emission over the ambient radiance, capped per sample (keeps the
// 16-bit sums finite when the environment is black; the output is clamped to 1 anyway).
const float kMaxEmissionRatio = 64.0;
const vec3 kLuma = vec3(0.2126, 0.7152, 0.0722);  // grey value of a colour (Rec. 709)
// MODE 3: the colour sums' ceiling (half floats overflow to inf above 65504).
const float kMaxHalfSum = 65000.0;

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
  // Guard: sky / far-plane pixels and pixels without geometry are open (O = W = 1).
  // 1 / distance 0 marks them for the filter (nothing is averaged into or out of them).
  if (isSky(depth) || !giGBufferIsGeometry(gTexel)) {
    imageStore(outSums, p, uvec4(packHalf2x16(vec2(1.0)), 0u, 0u, 0u));
    return;
  }

  mat4 proj = frame.proj;
  // Guards: a degenerate projection must not divide by zero.
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  float p20 = proj[2][0], p21 = proj[2][1], p22 = proj[2][2];
  vec2 ndc = (vec2(p) + 0.5) * 2.0 * frame.viewport.zw - 1.0;
  float dist = p32 / max(depth + p22, 1e-30);
  vec3 P = vec3((ndc.x + p20) * dist / p00, (ndc.y + p21) * dist / p11, -dist);
  vec3 N = safeNormalize(giGBufferNormal(gTexel), safeNormalize(-P, vec3(0.0, 0.0, 1.0)));

  // Tangent frame without a helper axis (Duff et al. 2017): never degenerates.
  float s = N.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + N.z);
  float b = N.x * N.y * a;
  vec3 T = vec3(1.0 + s * N.x * N.x * a, s * b, -s * N.x);
  vec3 B = vec3(b, s + N.y * N.y * a, -N.y);
  vec2 rot = obs.rotation[(p.y & 3) * 4 + (p.x & 3)].xy;  // interleave: 16 rotations
  vec3 Tr = rot.x * T + rot.y * B;
  vec3 Br = rot.x * B - rot.y * T;

  // Test points projected incrementally (x, y in pixels, w = view distance), as in ssao.comp.
  float R = obs.radius;
  vec2 halfSize = 0.5 * vec2(size);
  vec3 clipP = clipToPixels(P, p00, p11, p20, p21, halfSize),
       clipT = clipToPixels(R * Tr, p00, p11, p20, p21, halfSize),
       clipB = clipToPixels(R * Br, p00, p11, p20, p21, halfSize),
       clipN = clipToPixels(R * N, p00, p11, p20, p21, halfSize);
  float invP32 = 1.0 / p32;
  // Texel-centre slide (see ssao.comp): a point is moved, parallel to the tangent plane, onto
  // the view ray of the texel centre it is compared with, so a plane never occludes itself.
  vec2 g = vec2(N.x / p00, N.y / p11) * 2.0 * frame.viewport.zw;
  float NP = dot(N, P);
  float minK = -kSlideMinK * max(-P.z, 1e-20);

  float invAmbient = 0.0;
  vec3 la = vec3(0.0);
  if (MODE >= 2) {  // folded away below 2
    la = environmentIrradianceOverPi(frame, mat3(frame.invView) * N);
    invAmbient = 1.0 / max(dot(la, kLuma), 1e-6);  // guard: black environment
  }

  vec2 sizeF = vec2(size);
  float bias = obs.bias;
  float nSum = 0.0, dSum = 0.0;
  vec3 sent = vec3(0.0);  // MODE 3: sum of (1 - J) L_d(y)
  for (int i = 0; i < SAMPLES; ++i) {
    uint code = obs.kernel[i >> 2][i & 3];
    vec3 k = vec3(float(code & 2047u) * (2.0 / 2047.0) - 1.0,
                  float((code >> 11) & 2047u) * (2.0 / 2047.0) - 1.0,
                  float(code >> 22) * (1.0 / 1023.0));
    vec3 offset = clipT * k.x + clipB * k.y + clipN * k.z;
    bool inside = false;
    ivec2 hit = p;  // texel of the first inside point (its albedo stands for the occluder's)
    for (int j = 1; j <= POINTS; ++j) {
      float f = float(j) / float(POINTS);
      vec3 c = clipP + offset * f;
      float K = NP + R * k.z * f;
      float Kc = min(K, minK), w = max(c.z, kMinClipW);
      float r = 1.0 / (w * Kc);
      float invW = r * Kc, invK = r * w;
      vec2 pix = c.xy * invW;
      // Guard: points behind the camera or off screen count as outside (open).
      bool valid = c.z > kMinClipW && pix.x >= 0.0 && pix.y >= 0.0 && pix.x < sizeF.x &&
                   pix.y < sizeF.y;
      ivec2 t = ivec2(clamp(pix, vec2(0.0), sizeF - 1.0));
      float iS = (texelFetch(gDepth, t, 0).r + p22) * invP32;  // stored surface, 1 / distance
      float slid = invW + dot(g, vec2(t) + 0.5 - pix) * invK;
      float iQ = (K < minK && slid > 0.0) ? slid : invW;  // test point, 1 / distance
      // Inside when bias < zQ - zS < R (silhouette test), in inverse distances.
      float diff = iS - iQ, prod = iS * iQ;
      bool in_j = valid && diff > bias * prod && diff < R * prod;
      hit = (in_j && !inside) ? t : hit;
      inside = inside || in_j;
    }
    float J = inside ? 0.0 : 1.0;
    nSum += J;
    if (MODE != 0) {
      uvec4 occluder = giGBufferLoad(hit);
      float albedo = clamp(dot(giGBufferAlbedo(occluder), kLuma), 0.0, 1.0);
      dSum += J + (1.0 - J) * (1.0 - albedo);  // = 1 - (1 - J) a, without cancellation
      if (MODE == 2) {
        float e = max(dot(giGBufferEmission(occluder), kLuma), 0.0) * invAmbient;
        nSum += (1.0 - J) * min(e, kMaxEmissionRatio);
      }
      if (MODE == 3) sent += (1.0 - J) * max(texelFetch(gRadiance, hit, 0).rgb, vec3(0.0));
    }
  }
  float invN = 1.0 / float(SAMPLES);
  vec2 sums = vec2(nSum * invN, MODE == 0 ? 1.0 : dSum * invN);
  // MODE 3: the numerator in colour, with the transfer guard's phantom open sample (eta of it,
  // seeing L^a) added here, where L^a is known: the resolve divides (N + eta L^a) / (D + eta),
  // averaged over the filter's window. Guard: the sums stay below the half-float maximum.
  vec3 rgb = vec3(0.0);
  if (MODE == 3) {
    float eta = obs.guard;
    rgb = min(la * (sums.x + eta) + sent * invN, vec3(kMaxHalfSum));
    sums = vec2(rgb.r, sums.y + eta);
  }

  // For the filter: on the tangent plane N.X = N.P, 1/z along the pixel's view ray D (z = -1)
  // is (N.D) / (N.P), so its slope per pixel is (1/z) (N.x dDx, N.y dDy) / (N.D).
  float ic = 1.0 / dist;
  vec3 D = vec3((ndc.x + p20) / p00, (ndc.y + p21) / p11, -1.0);
  float nd = dot(N, D);
  vec2 dD = 2.0 * frame.viewport.zw / vec2(p00, p11);
  // Guard: a grazing normal (N.D near 0) predicts nothing: slope 0, so only neighbours at the
  // centre's own distance are averaged.
  vec2 slope = nd < -1e-4 * length(D) ? ic * N.xy * dD / nd : vec2(0.0);
  slope = clamp(slope, vec2(-60000.0), vec2(60000.0));  // finite in 16 bits
  imageStore(outSums, p,
             uvec4(packHalf2x16(sums), floatBitsToUint(ic), packHalf2x16(slope),
                   MODE == 3 ? packHalf2x16(rgb.gb) : 0u));
}
