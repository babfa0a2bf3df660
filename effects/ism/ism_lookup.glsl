// The maps (binding 5) and one VPL's irradiance with visibility, shared by the gathering and
// the bounce shaders. ISM_CLASSIC: accurate paraboloid depth maps (D32 reverse-Z, near..far);
// otherwise ISMs (r32ui distances, ISM_EMPTY where no point landed).
#ifndef ISM_LOOKUP_GLSL
#define ISM_LOOKUP_GLSL

#include "guards.glsl"

#ifdef ISM_CLASSIC
layout(set = 0, binding = 5) uniform sampler2D maps;
#else
layout(set = 0, binding = 5) uniform usampler2D maps;
#endif

float storedDistance(ivec2 t) {
#ifdef ISM_CLASSIC
  float z = texelFetch(maps, t, 0).r;  // reverse-Z: 0 = nothing up to far
  return ism.bias.z + (1.0 - z) * (ism.bias.w - ism.bias.z);
#else
  uint u = texelFetch(maps, t, 0).r;
  return u == ISM_EMPTY ? 3.0e38 : uintBitsToFloat(u);
#endif
}

// Irradiance at x (normal n) from VPL v whose map is tile `tile`: phi / pi cos_v cos_r /
// max(d^2, d_min^2) (the singularity guard) x visibility (constant + slope bias). d = 0 has no
// direction: 0.
vec3 vplIrradiance(Vpl v, uint tile, vec3 x, vec3 n) {
  vec3 w = x - v.position.xyz;
  float d2 = dot(w, w);
  float d = sqrt(d2);
  vec3 dir = d > 1e-10 ? w / d : v.normal.xyz;
  float cv = max(dot(v.normal.xyz, dir), 0.0);
  float cr = d > 1e-10 ? max(-dot(n, dir), 0.0) : 0.0;
  vec3 s, u;
  ismBasis(v.normal.xyz, s, u);
  ivec2 t = ismTexel(tile, dir, s, u, max(cv, 1e-4));
  float visible = d - (ism.bias.x + ism.bias.y * d) <= storedDistance(t) ? 1.0 : 0.0;
  // The VPL singularity clamp, counted where it changes a visible term.
  giGuard(GI_GUARD_DISTANCE, d2 < ism.gather.x && visible * cv * cr > 0.0);
  return v.flux.rgb * (visible * cv * cr / (3.14159265 * max(d2, ism.gather.x)));
}

// Irradiance at x (normal n) from environment VPL v (direction d to the sky, irradiance E at
// normal incidence) whose orthographic map is tile `tile`: E max(n.d, 0) x visibility. The
// receiver is looked up from x + n x ism.envVpls.w texels (normal offset: an orthographic
// texel holds one depth for a surface whose depth changes by texel x tan(theta) across it, so
// a depth bias alone either shadows the floor itself at low elevations or leaks under
// occluders), with the constant bias. Occluders within ism.nearField.x of the receiver along
// d are left to the "ao" that multiplies the result (0: none): the map holds the surface
// nearest the sky, so it is within that range only if every occluder on the way is.
vec3 envVplIrradiance(Vpl v, uint tile, vec3 x, vec3 n) {
  vec3 d = v.position.xyz, s, u;
  ismBasis(-d, s, u);
  vec3 xo = x + n * (ism.envVpls.w * ismOrthoTexelSide());
  ivec2 t = ismOrthoTexel(tile, xo, s, u);
#ifdef ISM_CLASSIC
  float stored = storedDistance(t) - ism.bias.z;  // the classic view's eye is near beyond R
#else
  float stored = storedDistance(t);
#endif
  float visible = ismOrthoDepth(xo, d) - max(ism.bias.x, ism.nearField.x) <= stored ? 1.0 : 0.0;
  return v.flux.rgb * (visible * max(dot(n, d), 0.0));
}

#endif
