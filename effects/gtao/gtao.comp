#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "common.glsl"
#include "depth_aware_blur.glsl"

// Ground-truth ambient occlusion (Jimenez et al. 2016, "Practical realtime strategies for
// accurate indirect occlusion"; RTR 4th ed. 11.3.7, eq. 11.18 with the cosine term). For each
// of kSlices planes through the view vector V (rotated per pixel by the 4x4 interleave), the
// depth buffer is marched kSteps times on each side for the highest horizon within the radius;
// the cosine-weighted visible arc between the two horizons (clamped to the normal's
// hemisphere) is integrated in closed form and weighted by the projected normal's length.
// Estimator details, guards and the bent normal: gtao_params.h and README.md.
//
// Assumes a perspective projection (clip.w = view distance), as every engine camera has.
layout(local_size_x = 32, local_size_y = 16) in;

// Specialization constants (set by the plugin at pipeline creation):
// the loops unroll and the optional outputs vanish when off (llvmpipe runs both sides of
// every branch, so a runtime `if` would cost the full price).
layout(constant_id = 0) const int kSlices = 3;
layout(constant_id = 1) const int kSteps = 3;
layout(constant_id = 2) const bool kBentNormals = false;
layout(constant_id = 3) const bool kMultiBounce = false;
// `downsample`: invocation q computes the frame pixel q x kScale, at 1 / kScale of the
// frame's resolution in each axis; the engine's blur upsamples (gi/depth_aware_blur.h).
layout(constant_id = 4) const int kScale = 1;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Keep in sync with gi::gtao::Uniforms (gtao_params.h).
layout(set = 0, binding = 1) uniform GtaoParams {
  float radius;        // R, world units
  float falloffSlope;  // 1 / (falloff x R)
  float thickness;     // horizon blend towards lower samples, 0 = off
  float pad;
  vec4 noise[16];  // per 4x4 phase: cos, sin of the slice rotation, step jitter in [0, 1), 0
} gtao;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"  // the packed G-buffer (normal; albedo for multi_bounce)
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D outAO;  // depthAwareBlurPack(Scaled)
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D outBent;  // 1x1 when off

const float kPi = 3.14159265358979;
const float kHalfPi = 1.57079632679490;

// View-space position of texel t's centre from its reverse-Z depth d; proj4 = (1 / P00,
// 1 / P11, P22, 0) (multiplications: llvmpipe divides slowly).
vec3 viewPosition(vec2 t, float d, vec4 proj4, vec2 off, float p32) {
  vec2 ndc = (t + 0.5) * 2.0 * frame.viewport.zw - 1.0;
  // Guard: depth + P22 <= 0 (sky, or the far plane of an infinite projection) would divide by
  // zero; such samples are rejected by the caller.
  float dist = p32 / max(d + proj4.z, 1e-30);
  return vec3((ndc + off) * proj4.xy * dist, -dist);
}

// One depth sample of horizonCos's march: the horizon cosine hc updated by step `step`.
float horizonStep(float hc, int step, float sgn, vec2 d, vec3 tangentLine, float invProjLen,
                  vec3 N, vec3 P, vec2 pixelCentre, float radiusPx, float R, float jitter,
                  vec2 sizeF, ivec2 size, vec4 proj4, vec2 off, float p32) {
  // Uniform steps with a jittered start (see gtao_params.h).
  float s = (float(step) + jitter) / float(kSteps);
  // Guard: the first sample is at least one pixel out, never the centre texel itself (a
  // zero-length offset has no direction).
  vec2 pix = pixelCentre + sgn * d * (s * radiusPx + 1.0);
  ivec2 t = ivec2(floor(pix));
  bool inside = pix.x >= 0.0 && pix.y >= 0.0 && pix.x < sizeF.x && pix.y < sizeF.y;
  float sd = texelFetch(gDepth, clamp(t, ivec2(0), size - 1), 0).r;
  vec3 delta = viewPosition(vec2(t), sd, proj4, off, p32) - P;
  float len = length(delta);
  float x = sgn * dot(delta, tangentLine), y = dot(delta, N) * invProjLen;
  // Guard: a zero offset has no direction (inversesqrt of 1e-30 stays finite).
  float ce = x * inversesqrt(max(x * x + y * y, 1e-30));
  // Falloff: full weight up to R (1 - falloff), none beyond R; the reference counts
  // occluders within R exactly (falloff 0 is its hard cut-off).
  float w = clamp((R - len) * gtao.falloffSlope, 0.0, 1.0);
  // Guards: off-screen and sky samples (depth 0: a point at infinity, len may overflow to inf
  // and ce be NaN) and samples below the tangent plane are not occluders; selects never
  // propagate the unselected NaN. Depth reconstruction leaves a plane's own samples within
  // ~1e-4 x len of it: heights below 1e-3 x len (0.06 degrees) count as on the plane.
  bool valid = inside && !isSky(sd) && w > 0.0 && y > 1e-3 * len;
  float cw = valid ? mix(1.0, ce, w) : 1.0;
  // Thickness heuristic (Jimenez et al. 2016, sec. 4.3): a sample below the horizon pulls it
  // down by the blend factor (0: the plain maximum).
  return cw < hc ? cw : mix(hc, cw, gtao.thickness);
}

// Up to this many steps per side the march is unrolled; beyond, it stays a loop. Measured on
// llvmpipe (README.md, "Cost"): unrolled, 1 slice x 4..6 steps cost ~1.5x the loop (10.3 vs
// 7.1 ms at 4 steps, 320x240), while 2..3 steps are ~10% cheaper unrolled.
const int kUnrollMaxSteps = 3;

// The cosine of the highest elevation above the slice's tangent line on one side (sgn = +1:
// towards +T) among kSteps depth samples within R; 1 = the tangent plane.
//
// Horizons are elevations above the tangent line of the slice (the normal's hemisphere edge),
// in the slice frame: x along that line, y along the normal. For samples in the slice plane
// this is the usual horizon angle from V; depth texels are sampled at their centres, off the
// slice by up to half a texel, and measuring their height along the normal (instead of their
// angle to V) keeps a plane's own samples exactly on the tangent line at any viewing angle: a
// plane never occludes itself.
float horizonCos(float sgn, vec2 d, vec3 tangentLine, float invProjLen, vec3 N, vec3 P,
                 vec2 pixelCentre, float radiusPx, float R, float jitter, vec2 sizeF, ivec2 size,
                 vec4 proj4, vec2 off, float p32) {
  float hc = 1.0;
  // kSteps is a specialization constant: one of the two loops is folded away.
  if (kSteps <= kUnrollMaxSteps) {
    for (int step = 0; step < kSteps; ++step)
      hc = horizonStep(hc, step, sgn, d, tangentLine, invProjLen, N, P, pixelCentre, radiusPx,
                       R, jitter, sizeF, size, proj4, off, p32);
  } else {
    [[dont_unroll]] for (int step = 0; step < kSteps; ++step)
      hc = horizonStep(hc, step, sgn, d, tangentLine, invProjLen, N, P, pixelCentre, radiusPx,
                       R, jitter, sizeF, size, proj4, off, p32);
  }
  return clamp(hc, -1.0, 1.0);  // guard: acos and sqrt(1 - c^2) need [-1, 1]
}

// Integral of cos(theta - n) |sin(theta)| from 0 to h (Jimenez et al. 2016, eq. 10): the
// cosine-weighted visible arc on one side of V in a slice. cs = (cos h, sin h), so that
// cos(2h - n) needs no trigonometry (llvmpipe evaluates each cos/acos as a long polynomial).
float arc(float h, vec2 cs, float cosN, float sinN) {
  float cos2h = 2.0 * cs.x * cs.x - 1.0, sin2h = 2.0 * cs.x * cs.y;
  return 0.25 * (cosN + 2.0 * h * sinN - (cos2h * cosN + sin2h * sinN));
}

// Int_0^h (cos(theta), sin(theta)) cos(theta - n) sin(theta) dtheta: the V and T components
// of the cosine-weighted directions on one side of V up to its horizon h (bent normals; the
// other side is the same with n -> -n and the T component negated).
vec2 bentArc(vec2 cs, float cosN, float sinN) {
  float c = cs.x, s = cs.y, c3 = c * c * c, s3 = s * s * s;
  return vec2(cosN * (1.0 - c3) + sinN * s3, cosN * s3 + sinN * (2.0 - 3.0 * c + c3)) / 3.0;
}

void main() {
  ivec2 q = ivec2(gl_GlobalInvocationID.xy);  // the output texel; p: the frame pixel it stands for
  ivec2 outSize = imageSize(outAO);
  if (q.x >= outSize.x || q.y >= outSize.y) return;
  ivec2 p = q * kScale;
  ivec2 size = ivec2(frame.viewport.xy);

  float depth = texelFetch(gDepth, p, 0).r;
  uvec4 gTexel = giGBufferLoad(p);
  // Guard: sky / far-plane pixels and pixels without geometry are open (selected at the end;
  // an early return saves nothing on llvmpipe).
  bool open = isSky(depth) || !giGBufferIsGeometry(gTexel);

  mat4 proj = frame.proj;
  // Guards: a degenerate projection must not divide by zero.
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p32 = abs(proj[3][2]) > 1e-30 ? proj[3][2] : 1e-30;
  vec4 proj4 = vec4(1.0 / p00, 1.0 / p11, proj[2][2], 0.0);
  vec2 off = vec2(proj[2][0], proj[2][1]);
  vec3 P = viewPosition(vec2(p), depth, proj4, off, p32);
  float dist = -P.z;
  // Guard: V = -P / |P| with |P| >= dist > 0.
  vec3 V = safeNormalize(-P, vec3(0.0, 0.0, 1.0));
  // Guard: a zero or NaN normal falls back to facing the camera.
  vec3 N = safeNormalize(giGBufferNormal(gTexel), V);

  float R = gtao.radius;
  // The radius in pixels at this depth (|P11| H / 2 pixels per unit at distance 1).
  float radiusPx = R * abs(p11) * 0.5 * frame.viewport.y / max(dist, 1e-30);
  // The phase of the output texel: the blur, which runs at the output's resolution, cancels it.
  vec4 noise = gtao.noise[(q.y & 3) * 4 + (q.x & 3)];
  vec2 pixelCentre = vec2(p) + 0.5;
  vec2 sizeF = vec2(size);
  // View-space offset per pixel of screen motion at constant depth: the slice plane through
  // the eye and the screen line holds V and this direction.
  vec2 viewPerPixel = 2.0 * frame.viewport.zw / vec2(p00, p11);

  float visible = 0.0, unoccluded = 0.0;
  vec3 bent = vec3(0.0);
  for (int slice = 0; slice < kSlices; ++slice) {
    // Slice angle pi slice / kSlices (folded at compile time once the loop unrolls), rotated by
    // the pixel's phase (its cos and sin come from the table).
    float base = float(slice) * (kPi / float(kSlices));
    vec2 cb = vec2(cos(base), sin(base));
    vec2 d = vec2(cb.x * noise.x - cb.y * noise.y, cb.y * noise.x + cb.x * noise.y);  // pixels
    vec3 dir3 = vec3(d * viewPerPixel, 0.0);
    // Guard: dir3 parallel to V needs a view ray at 90 degrees from the axis; fall back to any
    // perpendicular (the slice is then still a valid plane through V).
    vec3 T = safeNormalize(dir3 - dot(dir3, V) * V,
                           safeNormalize(cross(V, vec3(0, 1, 0)), vec3(1, 0, 0)));
    // The normal projected into the slice plane (span of V and T): its length weights the
    // slice, its angle n from V (towards T) centres the clamped hemisphere.
    float nt = dot(N, T), nv = dot(N, V);
    float projLen = sqrt(nt * nt + nv * nv);
    // Guard: back-facing normals (nv < 0) are clamped to n = +-pi/2 so that both horizons stay
    // on their own side of V (h0 <= 0 <= h1) and the arc formula holds; a zero projection
    // (atan(0, 0)) takes n = 0.
    float cv = max(nv, 0.0), lenN = sqrt(cv * cv + nt * nt);
    float cosN = lenN > 1e-12 ? cv / lenN : 1.0, sinN = lenN > 1e-12 ? nt / lenN : 0.0;
    float n = atan(sinN, cosN);

    vec3 tangentLine = T * cosN - V * sinN;  // towards +T
    // Guard: projLen -> 0 (a normal nearly perpendicular to the slice) only makes the slice's
    // weight vanish; 1e-6 keeps the scale finite.
    float invProjLen = 1.0 / max(projLen, 1e-6);
    // Two calls, not a loop over the sides: no array indexed by a loop counter (llvmpipe
    // would keep it in memory if the loop did not unroll).
    float c1 = horizonCos(1.0, d, tangentLine, invProjLen, N, P, pixelCentre, radiusPx, R,
                          noise.z, sizeF, size, proj4, off, p32);
    float c0 = horizonCos(-1.0, d, tangentLine, invProjLen, N, P, pixelCentre, radiusPx, R,
                          noise.z, sizeF, size, proj4, off, p32);
    // Horizon angles from V; clamped at V (an occluder on one side cannot hide the other side).
    float s1 = sqrt(1.0 - c1 * c1), s0 = sqrt(1.0 - c0 * c0);  // elevations in [0, pi]
    float h1 = n + kHalfPi - acos(c1);  // towards +T, in [0, n + pi/2] once clamped
    float h0 = n - kHalfPi + acos(c0);  // towards -T, in [n - pi/2, 0] once clamped
    // (cos h, sin h) by angle sums: h1 = n + pi/2 - e1, h0 = n - pi/2 + e0; (1, 0) at V.
    vec2 cs1 = h1 > 0.0 ? vec2(cosN * s1 - sinN * c1, cosN * c1 + sinN * s1) : vec2(1.0, 0.0);
    vec2 cs0 = h0 < 0.0 ? vec2(sinN * c0 + cosN * s0, sinN * s0 - cosN * c0) : vec2(1.0, 0.0);
    h1 = max(h1, 0.0);
    h0 = min(h0, 0.0);
    float v = projLen * (arc(h0, cs0, cosN, sinN) + arc(h1, cs1, cosN, sinN));
    visible += v;
    // Unoccluded: horizons at n -+ pi/2, arc sum = cos n + n sin n.
    unoccluded += projLen * (cosN + n * sinN);
    if (kBentNormals) {
      // The cosine-weighted mean visible direction of the slice, in closed form (exactly N
      // for an open hemisphere): the (V, T) components on each side of V.
      vec2 bp = bentArc(cs1, cosN, sinN), bm = bentArc(vec2(cs0.x, -cs0.y), cosN, -sinN);
      bent += projLen * (V * (bp.x + bm.x) + T * (bp.y - bm.y));
    }
  }
  // Ratio estimator: the slice sum over the same sum without occluders, so a plane gives
  // exactly 1 at any slice count. Guard: the denominator is >= projLen per slice, and projLen
  // is 0 only for a normal perpendicular to every slice plane (then: open).
  float ao = unoccluded > 1e-6 ? clamp(visible / unoccluded, 0.0, 1.0) : 1.0;

  if (kMultiBounce) {
    // Jimenez et al. 2016 multi-bounce fit on the albedo's luminance (cubic in AO, never
    // below AO: albedo 0 leaves it unchanged).
    vec3 albedo = giGBufferAlbedo(gTexel);
    float a = dot(albedo, vec3(0.2126, 0.7152, 0.0722));
    float fa = 2.0404 * a - 0.3324, fb = -4.7951 * a + 0.6417, fc = 2.7552 * a + 0.6903;
    ao = clamp(max(ao, ((fa * ao + fb) * ao + fc) * ao), 0.0, 1.0);
  }
  imageStore(outAO, q,
             depthAwareBlurPackScaled(frame, open ? 1.0 : ao, open ? vec3(0.0) : P, N, kScale));
  if (kBentNormals) {
    // Guard: no visible arc at all (fully occluded) or NaN falls back to the normal.
    vec3 bn = safeNormalize(bent, N);
    // Open pixels keep the G-buffer's normal (zero without geometry), as the "normal" view has.
    vec4 openValue = giGBufferIsGeometry(gTexel) ? vec4(giGBufferNormal(gTexel), 1.0) : vec4(0.0);
    // At a reduced resolution, the frame pixel's bent normal for its whole block (nearest
    // upsampling; the bent normal is not blurred either).
    for (int y = 0; y < kScale; ++y)
      for (int x = 0; x < kScale; ++x) {
        ivec2 t = p + ivec2(x, y);
        if (t.x < size.x && t.y < size.y) imageStore(outBent, t, open ? openValue : vec4(bn, 1.0));
      }
  }
}
