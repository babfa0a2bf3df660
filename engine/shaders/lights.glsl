// The scene's lights and shadow maps for the lighting pass and effects alike (C++ mirrors:
// gi/lights.h). Include after common.glsl, with the FrameUniforms block named `frame` declared,
// and after defining the set and bindings of the three resources:
//   #define GI_LIGHTS_SET 0
//   #define GI_LIGHTS_BINDING 6        // uniform buffer "lights"
//   #define GI_SHADOW_VIEWS_BINDING 7  // uniform buffer "shadow_views"
//   #define GI_SHADOW_MAPS_BINDING 8   // texture "shadow_maps" (sampler2DArray, nearest)
// Both tables are uniform buffers, not storage buffers: llvmpipe loads a storage buffer lane by
// lane even at a uniform index (a 96-byte shadow view per pixel cost ~13 ms at 640x480), a
// uniform buffer once. Hence the fixed maxima (gi::kMaxLights, gi::kMaxShadowViews).
// Optional, to drop code the scene does not need (e.g. from specialization constants):
//   GI_LIGHT_TYPES   bit mask of the light types present: 1 directional, 2 point, 4 spot
//   GI_SHADOW_TYPES  bit mask of the types of shadowed lights (0: no shadow code at all)
//   GI_PCF_RADIUS    PCF radius in texels (default: frame.options.x, at run time)
#ifndef GI_LIGHTS_GLSL
#define GI_LIGHTS_GLSL

#define GI_MAX_LIGHTS 128        // gi::kMaxLights
#define GI_MAX_SHADOW_VIEWS 160  // gi::kMaxShadowViews (16 KiB: every device's UBO limit)
#ifndef GI_LIGHT_TYPES
#define GI_LIGHT_TYPES 7
#endif
#ifndef GI_SHADOW_TYPES
#define GI_SHADOW_TYPES 7
#endif
#ifndef GI_PCF_RADIUS
#define GI_PCF_RADIUS clamp(int(frame.options.x), 0, 3)
#endif

struct Light {
  vec4 positionRange;   // view-space position, range (0: infinite)
  vec4 directionType;   // view-space direction the light points to, type (0 dir, 1 point, 2 spot)
  vec4 radiance;        // colour * intensity
  vec4 cone;            // cos(inner), cos(outer)
  vec4 shadow;          // first shadow view (-1: unshadowed), bias constant, bias slope, layer
};

// One rendered shadow view (a directional/spot map, or one cube face of a point light).
// Depth is reverse-Z (1 at the light's near plane, 0 at far) like the G-buffer.
struct ShadowView {
  mat4 viewToClip;  // camera view space -> light clip space
  vec4 params;      // perspective (1) or orthographic (0), near, far, texel footprint*
  vec4 tile;        // texel offset x, y and size of the view in its layer
};
// * world size of one texel: orthographic: params.w; perspective: params.w * light-space depth.

layout(set = GI_LIGHTS_SET, binding = GI_LIGHTS_BINDING, std140) uniform Lights {
  Light lights[GI_MAX_LIGHTS];
};
layout(set = GI_LIGHTS_SET, binding = GI_SHADOW_VIEWS_BINDING, std140) uniform ShadowViews {
  ShadowView shadowViews[GI_MAX_SHADOW_VIEWS];
};
layout(set = GI_LIGHTS_SET, binding = GI_SHADOW_MAPS_BINDING) uniform sampler2DArray shadowMaps;

int lightCount() { return GI_LIGHT_TYPES == 0 ? 0 : min(int(frame.params.y), GI_MAX_LIGHTS); }

// Guard: squared light distance is clamped so a light on the surface stays finite.
const float kMinLightDistance2 = 1e-4;

// Radiance arriving at view-space `pos` from light `light` without shadowing (irradiance
// normal to the light for a directional light), and the unit direction `l` toward the light.
vec3 lightIncident(Light light, vec3 pos, out vec3 l) {
  int type = GI_LIGHT_TYPES == 1 ? 0 : int(light.directionType.w);
  if ((GI_LIGHT_TYPES & 1) != 0 && type == 0) {
    l = safeNormalize(-light.directionType.xyz, vec3(0, 1, 0));
    return light.radiance.rgb;
  }
  vec3 toLight = light.positionRange.xyz - pos;
  float d2 = max(dot(toLight, toLight), kMinLightDistance2);
  l = toLight * inversesqrt(d2);
  float attenuation = 1.0 / d2;
  float range = light.positionRange.w;
  if (range > 0.0) {  // glTF's recommended smooth range window
    float r = d2 / (range * range);
    attenuation *= clamp(1.0 - r * r, 0.0, 1.0);
  }
  if ((GI_LIGHT_TYPES & 4) != 0 && type == 2) {
    float cd = dot(safeNormalize(light.directionType.xyz, vec3(0, -1, 0)), -l);
    attenuation *= smoothstep(light.cone.y, max(light.cone.x, light.cone.y + 1e-4), cd);
  }
  return light.radiance.rgb * attenuation;
}

// Fraction of the light reaching view-space position `pos` with unit normal `n` ((2r+1)^2 PCF,
// r = frame.options.x). `ndl` sets the slope-scaled part of the depth bias; with PCF the lookup
// moves off the surface along `n` (normal offset; n = vec3(0): none).
float shadowFactor(Light light, vec3 pos, vec3 n, float ndl) {
  int first = int(light.shadow.x);
  if (GI_SHADOW_TYPES == 0 || first < 0) return 1.0;
  // Directional and spot lights read their one view with the light's (uniform) index, which
  // llvmpipe loads once for all lanes; only a point light's face differs per pixel.
  ShadowView sv;
  if ((GI_SHADOW_TYPES & 2) != 0 && int(light.directionType.w) == 1) {  // point: major-axis face
    vec3 d = mat3(frame.invView) * (pos - light.positionRange.xyz);
    vec3 a = abs(d);
    int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    sv = shadowViews[min(first + 2 * axis + (d[axis] < 0.0 ? 1 : 0), GI_MAX_SHADOW_VIEWS - 1)];
  } else {
    sv = shadowViews[min(first, GI_MAX_SHADOW_VIEWS - 1)];
  }
  float near = sv.params.y, far = sv.params.z;
  bool perspective = sv.params.x > 0.5;
  float sinTheta = sqrt(max(1.0 - ndl * ndl, 0.0));
  int k = GI_PCF_RADIUS;
  // Normal offset: with PCF the lookup leaves the surface by the filter's reach (k + 1 texels),
  // scaled by sin theta (how far along the map a step along n goes). Every tap is compared with
  // the pixel's one biased depth; on a face lit at a grazing angle, a few texels wide in the
  // map, the kernel would otherwise reach the face's own continuation and the nearer face beside
  // it (a box's top seen above its front) and shadow the lit face in bands: the moire on the
  // Cornell box's blocks (tests/test_shadows.cpp, GrazingShadowTest).
  if (k > 0) {
    vec4 c0 = sv.viewToClip * vec4(pos, 1.0);
    float texel0 = sv.params.w * (perspective ? max(c0.w, 0.0) : 1.0);
    pos += n * (texel0 * (float(k) + 1.0) * sinTheta);
  }
  vec4 clip = sv.viewToClip * vec4(pos, 1.0);
  if (clip.w <= 0.0) return 1.0;
  vec3 ndc = clip.xyz / clip.w;
  vec2 uv = ndc.xy * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ndc.z < 0.0) return 1.0;
  float receiver = perspective ? clip.w : near + (1.0 - ndc.z) * (far - near);
  float texel = perspective ? sv.params.w * receiver : sv.params.w;
  float tanTheta = min(sinTheta / max(ndl, 1e-4), 10.0);
  float r = receiver - texel * (light.shadow.y + light.shadow.z * tanTheta);
  // The occluder test "biased receiver <= linear occluder depth" as a test on the stored
  // reverse-Z depth, once per pixel instead of a division per tap (both maps are monotonic):
  // perspective d -> near*far / (d*(far-near) + near), orthographic d -> near + (1-d)(far-near).
  // A tap is lit when its depth is at most the threshold (cleared 0 = nothing: lit too).
  float threshold = perspective ? (r > 0.0 ? near * (far / r - 1.0) / (far - near) : 1.0)
                                : 1.0 - (r - near) / (far - near);
  threshold = max(threshold, 0.0);
  int layer = int(light.shadow.w);
  ivec2 lo = ivec2(sv.tile.xy), size = ivec2(sv.tile.z), hi = lo + size - 1;
  ivec2 center = lo + clamp(ivec2(uv * vec2(size)), ivec2(0), size - 1);
  float lit = 0.0;
  for (int dy = -k; dy <= k; ++dy)
    for (int dx = -k; dx <= k; ++dx)
      lit += texelFetch(shadowMaps, ivec3(clamp(center + ivec2(dx, dy), lo, hi), layer), 0).r <=
                     threshold
                 ? 1.0
                 : 0.0;
  return lit / float((2 * k + 1) * (2 * k + 1));
}

// The same without the receiver's normal (no normal offset: PCF can shadow a face lit at a
// grazing angle in bands). Kept for effects written before the normal was passed.
float shadowFactor(Light light, vec3 pos, float ndl) {
  return shadowFactor(light, pos, vec3(0.0), ndl);
}

// The scene's lights at one surface point as the lighting pass evaluates them (Lambert +
// normalised Blinn-Phong, shadow maps): `irradiance` = sum of incident x cos x visibility (the
// diffuse radiance is diffuseColor x irradiance / pi), `specular` = the Blinn-Phong radiance
// toward `v` (f0 x normalised lobe x incident x cos x visibility). Channel i of `contact`
// multiplies the visibility of the i-th shadow-casting light, the first four in `lights` order
// (pass vec4(1.0) and useContact false for none). The one place this sum is written: the lighting
// pass and any effect that publishes "direct_light" (the pass's replacement) share it.
struct LightSum {
  vec3 irradiance;
  vec3 specular;
};

LightSum sumLights(vec3 pos, vec3 n, vec3 v, vec3 f0, float shininess, vec4 contact,
                   bool useContact) {
  LightSum sum = LightSum(vec3(0.0), vec3(0.0));
  int shadowed = 0;  // shadow-casting lights seen so far (the contact channel)
  int count = lightCount();
  for (int i = 0; i < count; ++i) {
    Light light = lights[i];
    // Counted before any `continue`: the channel follows `lights` order, not this pixel's.
    int channel = shadowed;
    if (useContact && light.shadow.x >= 0.0) ++shadowed;
    vec3 l;
    vec3 incident = lightIncident(light, pos, l);
    float ndl = max(dot(n, l), 0.0);
    if (ndl <= 0.0 || all(lessThanEqual(incident, vec3(0.0)))) continue;
    float visibility = shadowFactor(light, pos, n, ndl);
    if (useContact && light.shadow.x >= 0.0 && channel < 4)
      visibility *= clamp(contact[channel], 0.0, 1.0);
    if (visibility <= 0.0) continue;
    vec3 h = safeNormalize(l + v, n);
    float spec = (shininess + 8.0) / (8.0 * 3.14159265358979) * pow(max(dot(n, h), 0.0), shininess);
    vec3 e = incident * ndl * visibility;
    sum.irradiance += e;
    sum.specular += f0 * spec * e;
  }
  return sum;
}

// Blinn-Phong exponent of a G-buffer roughness (the lighting pass's mapping).
float shininessOf(float roughness) {
  float r = max(roughness, 0.03);
  return clamp(2.0 / (r * r * r * r) - 2.0, 1.0, 4096.0);
}

#endif
