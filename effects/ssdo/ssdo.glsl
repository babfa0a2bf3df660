#include "common.glsl"
#include "guards.glsl"

// Screen-space directional occlusion with one indirect bounce (Ritschel, Grosch, Seidel 2009;
// seed 000). Per pixel P with normal N, N samples Q_i = P + R s_i w_i (ssdo_samples.h: cosine-
// distributed w_i, s_i in (0, 1], one of 16 precomputed sets per 4x4 pixel phase). Q_i is
// projected; when the surface S_i seen at its pixel lies in front of Q_i (by more than the bias
// and less than R: the range guard, as SSAO's), direction w_i is blocked and S_i is a sender.
//   directional term  D = (1 / N) sum_i L_env(w_i) V_i        (x albedo later: `ambient`)
//   bounce term       B = sum_i (1 - V_i) L_s (A_s / pi) cos_s cos_r / max(d^2, d_min^2)
//                                                              (x albedo later: `indirect`)
// with A_s = pi R^2 / N x bounce_strength, cos_s = max(N_s . -r, 0) (back-facing senders give
// nothing), cos_r = max(N . r, 0), r the unit vector from P to S_i at distance d.
// L_env is the environment in world direction w_i as environmentRadiance() gives it (exact for
// the procedural sky and constant environments; for an equirect map its SH9 low-frequency
// part, irradiance / pi, summed through the open samples' moments: SH9 is quadratic in the
// direction), specialized to the environment's kind.
// Writes the raw terms with what the blur needs (ssdo_common.glsl).
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int kSamples = 12;  // 1..gi::ssdo::kMaxSamples: the loop unrolls
layout(constant_id = 1) const bool kBounce = true;
// The environment's kind (FrameUniforms.skyHorizon.w: 0 sky, 1 constant, 2 equirect map):
// evaluating all three per sample (llvmpipe runs every branch) would cost most of the pass.
layout(constant_id = 2) const int kEnvironmentKind = 0;

// Depth layers (1..4): with 2 a sample is blocked only inside the solid interval between the
// front layer and the peeled one (seed 000 §4, Fig. 5); where no second layer exists, the
// one-layer test with its range guard. With 3 and 4 also inside the next interval [layer 2,
// layer 3] (with 3, or where no fourth layer exists: layer 2 and the range guard).
layout(constant_id = 3) const int kLayers = 1;
// Additional cameras (0..4): a sample is also blocked when it is behind a surface one of them
// sees (same test, their own images), and that surface is then its sender.
layout(constant_id = 4) const int kCameras = 0;
// An equirect map's radiance per sample direction (kEnvironmentKind 2; setting
// `environment_sampling`): 0, its SH9 (the sum over the open samples' moments); 1, the map
// per direction (its texel: environment.glsl's environmentTexelRadiance) over the cosine-
// distributed samples;
// 2, the map with multiple importance sampling: the odd samples take their directions from the
// engine's importance sampling of the map (ssdo_env_samples.comp), the even ones stay cosine-
// distributed, and each is weighted by the balance heuristic, 2 L V (cos / pi) /
// (cos / pi + pdf_env) (guard: a zero denominator, or a direction below the horizon, adds 0).
// The bounce uses the cosine samples only (their patch area doubled in mode 2).
layout(constant_id = 5) const int kEnvironmentSampling = 0;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
#include "ssdo_common.glsl"
layout(set = 0, binding = 3, rgba32ui) uniform writeonly uimage2D outRaw;
#define GI_ENVIRONMENT_SET 0
#define GI_ENVIRONMENT_BINDING_MAP 11
#define GI_ENVIRONMENT_BINDING_SAMPLING 12
#include "environment.glsl"
#include "ssdo_env.glsl"
// The importance samples of `environment_sampling=mis`, one per sample slot (ssdo_env_samples).
layout(set = 0, binding = 13, std430) readonly buffer EnvironmentSamples {
  vec4 environmentSamples[];
};
#ifdef SSDO_DEPTH_INPUT
// Directional occlusion alone (no bounce, one layer, no cameras; ssdo_depth.comp): a tap needs
// only the 1 / view distance, which is affine in the G-buffer's reverse-Z depth, so the taps
// read the depth itself (32 bits, not the surface texel's 128) and ssdo_surface does not run.
// Bit for bit the same values as ssdo_surface.comp writes.
layout(set = 0, binding = 9) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 10
#include "gbuffer.glsl"  // the packed G-buffer (normals)
// 1 / view distance of reverse-Z depth d: (d + P22) / P32, as ssdo_surface.comp. Guards: sky,
// a degenerate projection and non-finite values read 0 (never an occluder).
float inverseDistance(float d, float p22, float p32) {
  float iz = abs(p32) > 1e-30 ? (d + p22) / p32 : 0.0;
  return !isSky(d) && iz > 0.0 && !isinf(iz) ? iz : 0.0;
}
#else
layout(set = 0, binding = 2) uniform usampler2D gSurface;  // ssdo_surface.comp
// The additional cameras' surface texels (ssdo_surface.comp through their views; unused ones
// are bound to gSurface).
layout(set = 0, binding = 4) uniform usampler2D gCamera0;
layout(set = 0, binding = 5) uniform usampler2D gCamera1;
layout(set = 0, binding = 6) uniform usampler2D gCamera2;
layout(set = 0, binding = 7) uniform usampler2D gCamera3;
// Layers 2 and 3 (ssdo_layers.comp: two half 1 / z in .x; kLayers > 2, else bound to gSurface).
layout(set = 0, binding = 8) uniform usampler2D gLayers23;
#endif

#ifndef SSDO_DEPTH_INPUT
// `c` is a constant after the camera loop unrolls: the branches fold.
uvec4 fetchCamera(int c, ivec2 t) {
  if (c == 0) return texelFetch(gCamera0, t, 0);
  if (c == 1) return texelFetch(gCamera1, t, 0);
  if (c == 2) return texelFetch(gCamera2, t, 0);
  return texelFetch(gCamera3, t, 0);
}
#endif

// Guard: samples at or behind the camera plane (clip.w below this) are untestable: open.
const float kMinClipW = 1e-20;
// Guard: float32 depth resolves view distances to ~2^-23 relative: an occluder must be at least
// this fraction of its distance in front of the sample (no banded self-occlusion at tiny radii).
const float kDepthResolution = 1e-6;
// Guard: the texel-centre slide is skipped when the sample's tangent-parallel plane passes this
// close to the camera (ill-conditioned), as in effects/ssao.
const float kSlideMinK = 1e-4;

vec3 clipToPixels(vec3 v, float p00, float p11, float p20, float p21, vec2 halfSize) {
  float w = -v.z;
  return vec3((vec2(p00 * v.x + p20 * v.z, p11 * v.y + p21 * v.z) + w) * halfSize, w);
}

// The bounce of one sender S (normal Ns, outgoing radiance Ls) at receiver P (normal N), view
// space. Guard: a sender at P (d -> 0) has no direction: r = N, then cos_s decides; the
// distance clamp d_min keeps 1 / d^2 finite (seed 000: the paper clamps d to 1).
vec3 sendFrom(vec3 S, vec3 Ns, vec3 Ls, vec3 P, vec3 N, float dMin2) {
  vec3 d = S - P;
  float d2 = dot(d, d);
  vec3 rdir = safeNormalize(d, N);
  float cosR = max(dot(N, rdir), 0.0);
  float cosS = max(-dot(Ns, rdir), 0.0);  // back-facing: 0
  giGuard(GI_GUARD_DISTANCE, d2 < dMin2 && cosS * cosR > 0.0);
  return Ls * (cosS * cosR / max(d2, dMin2));
}

// Sum over the open samples of the SH9 irradiance / pi (environmentIrradianceOverPi, without
// its per-direction clamp at 0: the sum is clamped) from the samples' count and moments in the
// tangent frame F (columns T', B', N in world space): sum d = F m1, sum d d^T = F S F^T.
vec3 shFromMoments(float count, vec3 m1, vec3 m2, vec3 m2x, mat3 F) {
  mat3 S = mat3(m2.x, m2x.x, m2x.y, m2x.x, m2.y, m2x.z, m2x.y, m2x.z, m2.z);
  mat3 D = F * S * transpose(F);  // D[j][i] = sum d_i d_j
  vec3 d = F * m1;
  vec3 e = frame.irradianceSH[0].rgb * (0.282095 * count) +
           frame.irradianceSH[1].rgb * (0.488603 * d.y) +
           frame.irradianceSH[2].rgb * (0.488603 * d.z) +
           frame.irradianceSH[3].rgb * (0.488603 * d.x) +
           frame.irradianceSH[4].rgb * (1.092548 * D[1][0]) +
           frame.irradianceSH[5].rgb * (1.092548 * D[2][1]) +
           frame.irradianceSH[6].rgb * (0.315392 * (3.0 * D[2][2] - count)) +
           frame.irradianceSH[7].rgb * (1.092548 * D[2][0]) +
           frame.irradianceSH[8].rgb * (0.546274 * (D[0][0] - D[1][1]));
  return max(e, vec3(0.0)) * (1.0 / 3.14159265358979);
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;

#ifdef SSDO_DEPTH_INPUT
  // What ssdo_surface.comp would have written here (x, y; no sender radiance, no layer).
  uvec4 gTexel = giGBufferLoad(p);
  float izG = inverseDistance(texelFetch(gDepth, p, 0).r, frame.proj[2][2], frame.proj[3][2]);
  uvec4 centre = uvec4(floatBitsToUint(giGBufferIsGeometry(gTexel) ? izG : 0.0),
                       giEncodeNormal(giGBufferNormal(gTexel)), 0u, 0u);
#else
  uvec4 centre = texelFetch(gSurface, p, 0);
#endif
  float iz = uintBitsToFloat(centre.x);
  // Guard: sky pixels and pixels without geometry get no samples (all terms 0).
  if (!(iz > 0.0)) {
    imageStore(outRaw, p, uvec4(0u, 0u, 0u, 0u));
    return;
  }
  mat4 proj = frame.proj;
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  float p20 = proj[2][0], p21 = proj[2][1], p22 = proj[2][2];
  float depthP32 = proj[3][2];  // unguarded: inverseDistance guards it as ssdo_surface does
  vec2 invSize = frame.viewport.zw;
  vec3 P = ssdoViewPosition(vec2(p) + 0.5, iz, invSize, p00, p11, p20, p21);
  vec3 N = giDecodeNormal(centre.y);

  // Tangent frame (Duff et al. 2017): never degenerate.
  float sg = N.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (sg + N.z);
  float b = N.x * N.y * a;
  vec3 T = vec3(1.0 + sg * N.x * N.x * a, sg * b, -sg * N.x);
  vec3 B = vec3(b, sg + N.y * N.y * a, -N.y);
  mat3 toWorld = mat3(frame.invView);
  vec3 Tw = toWorld * T, Bw = toWorld * B, Nw = toWorld * N;  // world frame of the samples

  float R = ssdo.radius;
  vec2 halfSize = 0.5 * vec2(size);
  vec3 clipP = clipToPixels(P, p00, p11, p20, p21, halfSize),
       clipT = clipToPixels(R * T, p00, p11, p20, p21, halfSize),
       clipB = clipToPixels(R * B, p00, p11, p20, p21, halfSize),
       clipN = clipToPixels(R * N, p00, p11, p20, p21, halfSize);
  float invP32 = 1.0 / p32;
  // Texel-centre slide (effects/ssao/ssao.comp): the sample is moved parallel to the tangent
  // plane onto the view ray of the texel centre it is compared with, so a flat surface never
  // occludes itself at grazing angles.
  vec2 g = vec2(N.x / p00, N.y / p11) * 2.0 * invSize;
  float NP = dot(N, P);
  float minK = -kSlideMinK * max(-P.z, 1e-20);

  vec2 sizeF = vec2(size);
  float bias = ssdo.bias;
  float dMin2 = ssdo.distanceClamp2;
  int base = ((p.y & 3) * 4 + (p.x & 3)) * 32;
  // Sky: the radiance depends on the world direction's y only, y = up . (T' kx + B' ky + N kz).
  vec3 up = vec3(Tw.y, Bw.y, Nw.y);
  vec3 skyZenith = frame.skyZenith.rgb * frame.skyZenith.w,
       skyHorizon = frame.skyHorizon.rgb * frame.skyZenith.w,
       skyGround = frame.skyGround.rgb * frame.skyZenith.w;
  // The additional cameras' views of the sample frame (the same construction in their
  // spaces: N.Q is invariant, so K follows from their N.P).
  vec3 camP[4], camT[4], camB[4], camN[4];
  vec4 camProj[4];
  vec2 camG[4], camSize[4], camInvSize[4];
  mat4 camFrom[4];  // hoisted: uniform-block reads in the sample loop cost llvmpipe dearly
  float camNP[4], camMinK[4];
  for (int c = 0; c < kCameras; ++c) {
    mat4 toC = ssdo.cameras[c].toCamera;
    mat3 rot = mat3(toC);
    vec4 q = ssdo.cameras[c].proj;
    q.x = abs(q.x) > 1e-30 ? q.x : 1e-30;
    q.y = abs(q.y) > 1e-30 ? q.y : 1e-30;
    camProj[c] = q;
    vec4 sz = ssdo.cameras[c].size;
    camSize[c] = sz.xy;
    camInvSize[c] = sz.zw;
    camFrom[c] = ssdo.cameras[c].fromCamera;
    vec2 hs = 0.5 * sz.xy;
    vec3 Pc = (toC * vec4(P, 1.0)).xyz, Nc = rot * N;
    camP[c] = clipToPixels(Pc, q.x, q.y, q.z, q.w, hs);
    camT[c] = clipToPixels(R * (rot * T), q.x, q.y, q.z, q.w, hs);
    camB[c] = clipToPixels(R * (rot * B), q.x, q.y, q.z, q.w, hs);
    camN[c] = clipToPixels(R * Nc, q.x, q.y, q.z, q.w, hs);
    camG[c] = vec2(Nc.x / q.x, Nc.y / q.y) * 2.0 * sz.zw;
    camNP[c] = dot(Nc, Pc);
    camMinK[c] = -kSlideMinK * max(-Pc.z, 1e-20);
  }
  vec3 direct = vec3(0.0), bounce = vec3(0.0);
  vec3 m1 = vec3(0.0), m2 = vec3(0.0), m2x = vec3(0.0);  // kind 2: sums of k, k_i^2, k_i k_j
  for (int i = 0; i < kSamples; ++i) {
    int f = base + i;
    uint code = ssdo.samples[f >> 2][f & 3];
    float kx = float(code & 4095u) * (2.0 / 4095.0) - 1.0;
    float ky = float((code >> 12) & 4095u) * (2.0 / 4095.0) - 1.0;
    float kz = sqrt(max(0.0, 1.0 - kx * kx - ky * ky));
    float s = float((code >> 24) + 1u) * (1.0 / 256.0);
    // Per-direction map radiance (kEnvironmentSampling > 0): the sample's L and, with MIS, the
    // pdf of the other strategy. The branch on i folds: the loop unrolls.
    bool mapLookup = kEnvironmentKind == 2 && kEnvironmentSampling > 0;
    bool fromEnvironment = mapLookup && kEnvironmentSampling == 2 && (i & 1) == 1;
    vec3 envL = vec3(0.0);
    float envPdf = 0.0;
    if (fromEnvironment) {
      // Slot f's sample (R2 points over the slots of all 16 phases; ssdo_env_samples.comp).
      vec4 dirPdf = environmentSamples[2 * f];
      envL = environmentSamples[2 * f + 1].rgb;
      envPdf = dirPdf.w;
      kx = dot(dirPdf.xyz, Tw);
      ky = dot(dirPdf.xyz, Bw);
      kz = dot(dirPdf.xyz, Nw);  // <= 0: below the horizon, weighted 0 below
    } else if (mapLookup) {
      vec3 wd = Tw * kx + Bw * ky + Nw * kz;
      envL = environmentTexelRadiance(wd);
      if (kEnvironmentSampling == 2) envPdf = environmentPdf(wd);
    }
    vec3 c = clipP + (clipT * kx + clipB * ky + clipN * kz) * s;
    float K = NP + R * s * kz;
    float Kc = min(K, minK), w = max(c.z, kMinClipW);
    float r = 1.0 / (w * Kc);
    float invW = r * Kc, invK = r * w;
    vec2 pix = c.xy * invW;
    // Guard: samples behind the camera or off screen count as unoccluded.
    bool valid = c.z > kMinClipW && pix.x >= 0.0 && pix.y >= 0.0 && pix.x < sizeF.x &&
                 pix.y < sizeF.y;
    ivec2 t = ivec2(clamp(pix, vec2(0.0), sizeF - 1.0));
#ifdef SSDO_DEPTH_INPUT
    float iS = inverseDistance(texelFetch(gDepth, t, 0).r, p22, depthP32);
    uvec4 surface = uvec4(0u);
#else
    uvec4 surface = texelFetch(gSurface, t, 0);
    float iS = uintBitsToFloat(surface.x);  // 0: sky, never in front
#endif
    float slid = invW + dot(g, vec2(t) + 0.5 - pix) * invK;
    float iQ = (K < minK && slid > 0.0) ? slid : invW;
    // max(bias, resolution x zQ) < zQ - zS < R (range guard), in inverse distances.
    float diff = iS - iQ, prod = iS * iQ;
    bool inFront = valid && diff > max(bias * prod, kDepthResolution * iS);
    // Two layers: inside the solid interval [front, back] (1/z between them), wherever a back
    // layer exists; else the range guard.
    float iB = kLayers > 1 ? unpackHalf2x16(surface.w).y : 0.0;
    bool blocked = inFront && (iB > 0.0 ? iQ > iB : diff < R * prod);
    // Three or four layers: behind the back layer, the next solid interval [layer 2, layer 3]
    // (the same bias; no layer 3: the range guard from layer 2). Its surfaces are hidden: they
    // block, but their normal and radiance are unknown, so they send nothing (an additional
    // camera that sees the blocker below may).
    // Fetched only for samples behind the back layer (most are in front of the front one).
    bool hidden = false;
    if (kLayers > 2 && valid && !blocked && iB > 0.0 && iQ < iB) {
#ifndef SSDO_DEPTH_INPUT
      vec2 l23 = unpackHalf2x16(texelFetch(gLayers23, t, 0).x);
#else
      vec2 l23 = vec2(0.0);
#endif
      float diff2 = l23.x - iQ, prod2 = l23.x * iQ;
      hidden = l23.x > 0.0 && diff2 > max(bias * prod2, kDepthResolution * l23.x) &&
               (l23.y > 0.0 ? iQ > l23.y : diff2 < R * prod2);
    }
    vec3 send = vec3(0.0);
    if (kBounce) {
      vec3 S = ssdoViewPosition(vec2(t) + 0.5, max(iS, 1e-30), invSize, p00, p11, p20, p21);
      vec3 Ls = vec3(unpackHalf2x16(surface.z), unpackHalf2x16(surface.w).x);
      send = blocked ? sendFrom(S, giDecodeNormal(surface.y), Ls, P, N, dMin2) : vec3(0.0);
    }
    for (int cam = 0; cam < kCameras; ++cam) {
      // The same test in camera `cam`'s image (one layer, range guard, texel-centre slide).
      vec4 q = camProj[cam];
      vec3 cc = camP[cam] + (camT[cam] * kx + camB[cam] * ky + camN[cam] * kz) * s;
      float Kq = camNP[cam] + R * s * kz;
      float Kcl = min(Kq, camMinK[cam]), wc = max(cc.z, kMinClipW);
      float rc = 1.0 / (wc * Kcl);
      float invWc = rc * Kcl, invKc = rc * wc;
      vec2 pc = cc.xy * invWc;
      vec2 szc = camSize[cam];
      bool validC = cc.z > kMinClipW && pc.x >= 0.0 && pc.y >= 0.0 && pc.x < szc.x &&
                    pc.y < szc.y;
      ivec2 tc = ivec2(clamp(pc, vec2(0.0), szc - 1.0));
#ifndef SSDO_DEPTH_INPUT
      uvec4 sc = fetchCamera(cam, tc);
#else
      uvec4 sc = uvec4(0u);
#endif
      float iSc = uintBitsToFloat(sc.x);
      float slidC = invWc + dot(camG[cam], vec2(tc) + 0.5 - pc) * invKc;
      float iQc = (Kq < camMinK[cam] && slidC > 0.0) ? slidC : invWc;
      float diffC = iSc - iQc, prodC = iSc * iQc;
      bool blockedC = validC && diffC > max(bias * prodC, kDepthResolution * iSc) &&
                      diffC < R * prodC;
      if (kBounce) {
        // The first view that blocks the sample gives its sender (main view first).
        vec3 Sc = ssdoViewPosition(vec2(tc) + 0.5, max(iSc, 1e-30), camInvSize[cam], q.x, q.y,
                                   q.z, q.w);
        mat4 fromC = camFrom[cam];
        vec3 S = (fromC * vec4(Sc, 1.0)).xyz;
        vec3 Ns = mat3(fromC) * giDecodeNormal(sc.y);
        vec3 Ls = vec3(unpackHalf2x16(sc.z), unpackHalf2x16(sc.w).x);
        send = (!blocked && blockedC) ? sendFrom(S, Ns, Ls, P, N, dMin2) : send;
      }
      blocked = blocked || blockedC;
    }
    blocked = blocked || hidden;

    if (kEnvironmentKind == 1) {
      direct.x += blocked ? 0.0 : 1.0;  // constant: count the open directions
    } else if (mapLookup) {
      float cosPdf = max(kz, 0.0) * (1.0 / 3.14159265358979);
      float weight = kEnvironmentSampling == 1 ? 1.0
                                               : 2.0 * cosPdf / max(cosPdf + envPdf, 1e-30);
      direct += blocked ? vec3(0.0) : envL * weight;
    } else if (kEnvironmentKind == 2) {
      // SH9 (a quadratic polynomial of the direction): the open directions' moments suffice.
      vec3 k = vec3(kx, ky, kz);
      float open = blocked ? 0.0 : 1.0;
      direct.x += open;
      m1 += open * k;
      m2 += open * k * k;
      m2x += open * vec3(kx * ky, kx * kz, ky * kz);
    } else {
      float y = clamp(dot(up, vec3(kx, ky, kz)), -1.0, 1.0);
      vec3 sky = mix(skyHorizon, y >= 0.0 ? skyZenith : skyGround, sqrt(abs(y)));
      direct += blocked ? vec3(0.0) : sky;
    }
    // With MIS only the cosine samples send, each standing for twice the patch area.
    if (kEnvironmentSampling == 2 && kEnvironmentKind == 2)
      send = fromEnvironment ? vec3(0.0) : 2.0 * send;
    bounce += send;
  }
  if (kEnvironmentKind == 1) direct = direct.x * frame.skyGround.rgb * frame.skyZenith.w;
  if (kEnvironmentKind == 2 && kEnvironmentSampling == 0)
    direct = shFromMoments(direct.x, m1, m2, m2x, mat3(Tw, Bw, Nw));
  direct *= 1.0 / float(kSamples);
  bounce *= ssdo.bounceScale;
  imageStore(outRaw, p,
             uvec4(packRgb9e5(direct), packRgb9e5(bounce), centre.x, packBlurNormal(N)));
}
