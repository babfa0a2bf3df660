#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Contact shadows under the shadow-map bias (seed 000 §5). The lighting pass tests a receiver
// pushed toward the light by b = texel x (bias constant + bias slope x tan theta) (lights.glsl,
// shadowFactor; with PCF also moved off the surface by (r + 1) texels x sin theta along the
// normal), so an occluder closer than b along the light is missed: the shadow detaches
// from the contact. Per pixel P and per shadow-casting light i (the first four in `lights`
// order), kSamples points Q_k = P + t_k b l on that segment (t_k = (k + 1) / kSamples, l toward
// the light) are projected and tested against the surface S seen at their pixel; channel i =
// 1 - blocked / kSamples, which the lighting pass multiplies into light i's shadow factor
// ("contact_shadow"). Q is blocked when S lies in front of it (by at most kRangeScale x b) and
// Q lies behind S's tangent plane: a receiver never blocks itself (Q is above its plane), and
// the pixel grid's depth steps on grazing planes do not either.
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int kSamples = 4;      // 1..16: the loop unrolls
layout(constant_id = 1) const int kLightTypes = 7;   // bit mask: 1 directional, 2 point, 4 spot
layout(constant_id = 2) const int kShadowTypes = 7;  // the same for shadowed lights
#define GI_LIGHT_TYPES kLightTypes
#define GI_SHADOW_TYPES kShadowTypes

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
#include "ssdo_common.glsl"
// The G-buffer's depth and normal (not ssdo_surface's texel: with the bounce, ssdo_surface
// reads this pass's output to apply it to the direct light it publishes).
layout(set = 0, binding = 2) uniform sampler2D gDepth;
#define GI_LIGHTS_SET 0
#define GI_LIGHTS_BINDING 3
#define GI_SHADOW_VIEWS_BINDING 4
#define GI_SHADOW_MAPS_BINDING 5
#include "lights.glsl"
layout(set = 0, binding = 6, rgba8) uniform writeonly image2D outContact;
#define GI_GBUFFER_BINDING 7
#include "gbuffer.glsl"  // the packed G-buffer (normals)

// 1 / view distance at pixel t from the reverse-Z depth ((d + P22) / P32, affine in d);
// guards: sky, pixels without geometry and a degenerate projection read 0 (never in front).
float inverseDepthAt(ivec2 t, float p22, float p32) {
  float d = texelFetch(gDepth, t, 0).r;
  float iz = abs(p32) > 1e-30 ? (d + p22) / p32 : 0.0;
  return isSky(d) || !(iz > 0.0) || isinf(iz) ? 0.0 : iz;
}

// An occluder may lie up to this many bias lengths in front of Q along the view ray (Q is at
// most b inside it along the light; the view ray crosses the same solid more obliquely).
const float kRangeScale = 2.0;
// Guard: Q must be this fraction of its distance behind S's plane (float noise on the plane).
const float kPlaneEpsilon = 1e-5;
const float kMinClipW = 1e-20;

// The bias length b of `light` at view-space `pos` (world units along the light), as
// shadowFactor computes it; 0 behind a perspective view. The view is read at the light's
// (uniform) index only: a point light's six faces share near, far and texel footprint, and the
// major-axis face's view depth is the largest |component| of pos - light (a per-pixel face
// index would make llvmpipe load the view lane by lane).
float biasLength(Light light, vec3 pos, float ndl) {
  ShadowView sv = shadowViews[clamp(int(light.shadow.x), 0, GI_MAX_SHADOW_VIEWS - 1)];
  bool perspective = sv.params.x > 0.5;
  float receiver;
  if ((GI_SHADOW_TYPES & 2) != 0 && int(light.directionType.w) == 1) {
    vec3 a = abs(mat3(frame.invView) * (pos - light.positionRange.xyz));
    receiver = max(a.x, max(a.y, a.z));
  } else {
    vec4 clip = sv.viewToClip * vec4(pos, 1.0);
    if (clip.w <= 0.0) return 0.0;
    receiver = perspective ? clip.w
                           : sv.params.y + (1.0 - clip.z / clip.w) * (sv.params.z - sv.params.y);
  }
  float texel = perspective ? sv.params.w * receiver : sv.params.w;
  float tanTheta = min(sqrt(max(1.0 - ndl * ndl, 0.0)) / max(ndl, 1e-4), 10.0);
  return max(texel * (light.shadow.y + light.shadow.z * tanTheta), 0.0);
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  mat4 proj = frame.proj;
  float p22 = proj[2][2], p32 = proj[3][2];
  uvec4 g = giGBufferLoad(p);
  float iz = giGBufferIsGeometry(g) ? inverseDepthAt(p, p22, p32) : 0.0;
  float p00 = abs(proj[0][0]) > 1e-30 ? proj[0][0] : 1e-30;
  float p11 = abs(proj[1][1]) > 1e-30 ? proj[1][1] : 1e-30;
  float p20 = proj[2][0], p21 = proj[2][1];
  vec2 invSize = frame.viewport.zw, sizeF = vec2(size), halfSize = 0.5 * sizeF;
  // Guard: sky pixels (1 / z = 0) are left open (the loop still runs masked on llvmpipe).
  bool geometry = iz > 0.0;
  vec3 P = ssdoViewPosition(vec2(p) + 0.5, max(iz, 1e-30), invSize, p00, p11, p20, p21);
  vec3 N = giGBufferNormal(g);

  vec4 result = vec4(1.0);
  int shadowed = 0;
  int count = GI_SHADOW_TYPES == 0 ? 0 : lightCount();
  for (int i = 0; i < count && shadowed < 4; ++i) {
    Light light = lights[i];
    if (light.shadow.x < 0.0) continue;
    vec3 l;
    lightIncident(light, P, l);
    float ndl = max(dot(N, l), 0.0);
    float b = geometry && ndl > 0.0 ? biasLength(light, P, ndl) : 0.0;
    float blocked = 0.0;
    for (int k = 0; k < kSamples; ++k) {
      vec3 Q = P + (float(k + 1) / float(kSamples)) * b * l;
      float w = -Q.z;
      vec2 pix = (vec2(p00 * Q.x + p20 * Q.z, p11 * Q.y + p21 * Q.z) / max(w, kMinClipW) + 1.0) *
                 halfSize;
      bool valid = b > 0.0 && w > kMinClipW && pix.x >= 0.0 && pix.y >= 0.0 &&
                   pix.x < sizeF.x && pix.y < sizeF.y;
      ivec2 t = ivec2(clamp(pix, vec2(0.0), sizeF - 1.0));
      float iS = inverseDepthAt(t, p22, p32);  // 0: sky, never in front
      vec3 S = ssdoViewPosition(vec2(t) + 0.5, max(iS, 1e-30), invSize, p00, p11, p20, p21);
      float zS = -S.z;
      bool inFront = iS > 0.0 && zS < w && w - zS < kRangeScale * b;
      bool behindPlane = dot(giGBufferNormal(t), Q - S) < -kPlaneEpsilon * w;
      blocked += valid && inFront && behindPlane ? 1.0 : 0.0;
    }
    result[shadowed] = 1.0 - blocked / float(kSamples);
    ++shadowed;
  }
  imageStore(outContact, p, result);
}
