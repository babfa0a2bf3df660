#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "depth_aware_blur.glsl"

// Horizon-based ambient occlusion (Bavoil, Sainz and Dimitrov 2008, "Image-space horizon-based
// ambient occlusion"). For kDirections screen directions (rotated per pixel by the 4x4
// interleave), the depth buffer is marched kSteps times; elevation angles are measured from the
// view-space image plane. The horizon starts at the tangent angle t plus the angle bias, and
// each sample that rises above it adds W(r) (sin(elevation) - sin(horizon)) before becoming the
// horizon (horizon-split integration with per-sample attenuation W(r) = 1 - r^2 / R^2).
// AO = 1 - mean over directions. Details and guards: hbao_params.h and README.md.
//
// Assumes a perspective projection (clip.w = view distance), as every engine camera has.
layout(local_size_x = 32, local_size_y = 16) in;

// Specialization constants set at pipeline creation by the plugin: the loops unroll.
layout(constant_id = 0) const int kDirections = 6;
layout(constant_id = 1) const int kSteps = 4;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// Keep in sync with gi::hbao::Uniforms (hbao_params.h).
layout(set = 0, binding = 1) uniform HbaoParams {
  float radius;      // R, world units
  float invRadius2;  // 1 / R^2
  float cosBias, sinBias;  // of the angle bias
  vec4 noise[16];  // per 4x4 phase: cos, sin of the direction rotation, step jitter, 0
} hbao;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 3
#include "gbuffer.glsl"  // the packed G-buffer
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D outAO;  // depthAwareBlurPack

const float kPi = 3.14159265358979;
const float kHalfPi = 1.57079632679490;

// View-space position of texel t's centre from its reverse-Z depth d; proj4 = (1 / P00,
// 1 / P11, P22, 0) (multiplications: llvmpipe divides slowly).
vec3 viewPosition(vec2 t, float d, vec4 proj4, vec2 off, float p32) {
  vec2 ndc = (t + 0.5) * 2.0 * frame.viewport.zw - 1.0;
  // Guard: depth + P22 <= 0 (sky) would divide by zero; such samples are rejected.
  float dist = p32 / max(d + proj4.z, 1e-30);
  return vec3((ndc + off) * proj4.xy * dist, -dist);
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;

  float depth = texelFetch(gDepth, p, 0).r;
  uvec4 gTexel = giGBufferLoad(p);
  // Guard: sky / far-plane pixels and pixels without geometry are open (selected at the end).
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
  // Guard: |P| >= dist > 0; a zero or NaN normal falls back to facing the camera.
  vec3 Pn = safeNormalize(P, vec3(0.0, 0.0, -1.0));
  vec3 N = safeNormalize(giGBufferNormal(gTexel), -Pn);

  float R = hbao.radius, invR2 = hbao.invRadius2;
  float cosBias = hbao.cosBias, sinBias = hbao.sinBias;
  float radiusPx = R * abs(p11) * 0.5 * frame.viewport.y / max(dist, 1e-30);
  vec4 noise = hbao.noise[(p.y & 3) * 4 + (p.x & 3)];
  vec2 pixelCentre = vec2(p) + 0.5;
  vec2 sizeF = vec2(size);
  vec2 viewPerPixel = 2.0 * frame.viewport.zw / vec2(p00, p11);

  float occlusion = 0.0;
  for (int dir = 0; dir < kDirections; ++dir) {
    // Direction angle 2 pi dir / kDirections (folded at compile time once the loop unrolls),
    // rotated by the pixel's phase (its cos and sin come from the table): no trigonometry per
    // pixel (llvmpipe evaluates each sin/cos/asin as a long polynomial).
    float base = float(dir) * (2.0 * kPi / float(kDirections));
    vec2 cb = vec2(cos(base), sin(base));
    vec2 d = vec2(cb.x * noise.x - cb.y * noise.y, cb.y * noise.x + cb.x * noise.y);  // pixels
    vec3 dir3 = vec3(d * viewPerPixel, 0.0);  // view-space motion per pixel at this depth
    // Tangent angle t: elevation of the tangent plane's line in this direction's slice (the
    // plane through the eye holding P and dir3, where the samples lie), so that a plane's own
    // samples lie exactly on the tangent and never occlude it (Bavoil et al. step along the
    // view-space xy direction instead, which is off the slice away from the image centre).
    vec3 Dn = safeNormalize(dir3, vec3(1.0, 0.0, 0.0));
    vec3 tangent = cross(N, cross(Pn, Dn));
    // Orient it to the +d side: its component along Dn orthogonal to P must be positive.
    tangent = dot(tangent, Dn - dot(Dn, Pn) * Pn) < 0.0 ? -tangent : tangent;
    float lenT = length(tangent);
    // Guard: an edge-on surface (the tangent plane is the slice plane: no line) takes t = 0.
    float sinT = lenT > 1e-6 ? clamp(tangent.z / lenT, -1.0, 1.0) : 0.0;
    float cosT = sqrt(1.0 - sinT * sinT);  // t in [-pi/2, pi/2]
    // Samples are measured in the slice frame: x along the tangent line, y along the normal
    // (scaled by 1 / |normal projected into the slice|): their elevation is t + atan(y, x).
    // Depth texels are sampled at their centres, off the slice by up to half a texel; measured
    // this way a plane's own samples stay exactly on the tangent line at any viewing angle.
    vec3 tangentLine = tangent / max(lenT, 1e-6);
    float nAxis = dot(N, safeNormalize(cross(Pn, Dn), vec3(0.0, 1.0, 0.0)));
    // Guard: a normal nearly perpendicular to the slice keeps a finite scale.
    float invProjLen = inversesqrt(max(1.0 - nAxis * nAxis, 1e-12));
    // sin(t + bias); guard: the biased horizon is clamped to 90 degrees (sin stays monotone).
    float sinH = cosT * cosBias - sinT * sinBias < 0.0 ? 1.0 : sinT * cosBias + cosT * sinBias;
    float ao = 0.0;
    for (int step = 0; step < kSteps; ++step) {
      // Uniform steps with a jittered start; guard: at least one pixel out (a zero offset has
      // no elevation).
      float s = (float(step) + noise.z) / float(kSteps);
      vec2 pix = pixelCentre + d * (s * radiusPx + 1.0);
      ivec2 q = ivec2(floor(pix));
      bool inside = pix.x >= 0.0 && pix.y >= 0.0 && pix.x < sizeF.x && pix.y < sizeF.y;
      float sd = texelFetch(gDepth, clamp(q, ivec2(0), size - 1), 0).r;
      vec3 delta = viewPosition(vec2(q), sd, proj4, off, p32) - P;
      float r2 = dot(delta, delta);
      float x = dot(delta, tangentLine), y = dot(delta, N) * invProjLen;
      // Guard: a zero offset has no elevation (inversesqrt of 1e-30 stays finite).
      float invLen = inversesqrt(max(x * x + y * y, 1e-30));
      // sin and cos of t + atan(y, x); past the vertical the elevation is clamped to 90 deg.
      float sinE = (sinT * x + cosT * y) * invLen, cosE = (cosT * x - sinT * y) * invLen;
      sinE = cosE < 0.0 ? 1.0 : sinE;
      // Guard: off-screen and sky samples (a point at infinity: r2 may be inf, sinE NaN),
      // samples below the tangent plane and samples beyond R are ignored; selects never
      // propagate the unselected NaN.
      // Guard: depth reconstruction leaves a plane's own samples within ~1e-4 x r of it:
      // heights below 1e-3 x r (0.06 degrees) count as on the plane, not above it.
      bool valid = inside && !isSky(sd) && y > 1e-3 * sqrt(r2) && r2 < R * R;
      float gain = valid ? max(sinE - sinH, 0.0) * (1.0 - r2 * invR2) : 0.0;
      ao += gain;
      sinH = valid ? max(sinH, sinE) : sinH;
    }
    occlusion += ao;
  }
  float visibility = clamp(1.0 - occlusion / float(kDirections), 0.0, 1.0);
  imageStore(outAO, p, depthAwareBlurPack(frame, open ? 1.0 : visibility, open ? vec3(0.0) : P, N));
}
