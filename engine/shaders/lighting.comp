#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Direct lighting from the G-buffer: Lambert + normalised Blinn-Phong for point, spot and
// directional lights with PCF shadow maps, plus the environment's ambient term (SH9
// irradiance x AO). Writes linear HDR radiance.
layout(local_size_x = 8, local_size_y = 8) in;

struct Light {
  vec4 positionRange;   // view-space position, range (0: infinite)
  vec4 directionType;   // view-space direction the light points to, type (0 dir, 1 point, 2 spot)
  vec4 radiance;        // colour * intensity
  vec4 cone;            // cos(inner), cos(outer)
  vec4 shadow;          // first shadow view (-1: unshadowed), bias constant, bias slope, map slot
};

// One rendered shadow view (a directional/spot map, or one cube face of a point light).
// Depth is reverse-Z (1 at the light's near plane, 0 at far) like the G-buffer.
struct ShadowView {
  mat4 viewToClip;  // camera view space -> light clip space
  vec4 params;      // perspective (1) or orthographic (0), near, far, texel footprint*
  vec4 tile;        // texel offset x, y and size of the view in its map; point: 1
};
// * world size of one texel: orthographic: params.w; perspective: params.w * light-space depth.

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D gDepth;
layout(set = 0, binding = 2) uniform sampler2D gNormal;
layout(set = 0, binding = 3) uniform sampler2D gAlbedo;
layout(set = 0, binding = 4) uniform sampler2D gMaterial;
layout(set = 0, binding = 5) uniform sampler2D gEmission;
layout(set = 0, binding = 6, std430) readonly buffer Lights { Light lights[]; };
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D outLit;
// Ambient occlusion of the environment term (any resolution; a 1x1 white texture when no
// effect produces AO, so lighting works either way).
layout(set = 0, binding = 8) uniform sampler2D aoTexture;
// Shadow maps of up to four shadowed lights (D32, nearest; unused slots get a dummy).
layout(set = 0, binding = 9) uniform sampler2D shadowMap0;
layout(set = 0, binding = 10) uniform sampler2D shadowMap1;
layout(set = 0, binding = 11) uniform sampler2D shadowMap2;
layout(set = 0, binding = 12) uniform sampler2D shadowMap3;
layout(set = 0, binding = 13, std430) readonly buffer ShadowViews { ShadowView shadowViews[]; };
// Equirect environment map (kind 2; a 1x1 dummy otherwise).
layout(set = 0, binding = 14) uniform sampler2D environmentMap;

const float PI = 3.14159265358979;
// Guard: squared light distance is clamped so a light on the surface stays finite.
const float kMinLightDistance2 = 1e-4;

float shadowDepth(int slot, ivec2 t) {
  if (slot == 0) return texelFetch(shadowMap0, t, 0).r;
  if (slot == 1) return texelFetch(shadowMap1, t, 0).r;
  if (slot == 2) return texelFetch(shadowMap2, t, 0).r;
  return texelFetch(shadowMap3, t, 0).r;
}

// Fraction of the light reaching view-space position `pos` (3x3 PCF). `ndl` sets the
// slope-scaled part of the bias.
float shadowFactor(Light light, vec3 pos, float ndl) {
  int first = int(light.shadow.x);
  if (first < 0) return 1.0;
  int view = first;
  if (int(light.directionType.w) == 1) {  // point: the cube face of the major axis
    vec3 d = mat3(frame.invView) * (pos - light.positionRange.xyz);
    vec3 a = abs(d);
    int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    view += 2 * axis + (d[axis] < 0.0 ? 1 : 0);
  }
  ShadowView sv = shadowViews[view];
  vec4 clip = sv.viewToClip * vec4(pos, 1.0);
  if (clip.w <= 0.0) return 1.0;
  vec3 ndc = clip.xyz / clip.w;
  vec2 uv = ndc.xy * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ndc.z < 0.0) return 1.0;
  float near = sv.params.y, far = sv.params.z;
  bool perspective = sv.params.x > 0.5;
  float receiver = perspective ? clip.w : near + (1.0 - ndc.z) * (far - near);
  float texel = perspective ? sv.params.w * receiver : sv.params.w;
  float tanTheta = min(sqrt(max(1.0 - ndl * ndl, 0.0)) / max(ndl, 1e-4), 10.0);
  float bias = texel * (light.shadow.y + light.shadow.z * tanTheta);
  int slot = int(light.shadow.w);
  ivec2 lo = ivec2(sv.tile.xy), size = ivec2(sv.tile.z);
  ivec2 center = lo + clamp(ivec2(uv * vec2(size)), ivec2(0), size - 1);
  float lit = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 t = clamp(center + ivec2(dx, dy), lo, lo + size - 1);
      float d = shadowDepth(slot, t);
      // Linear light-space depth of the occluder (reverse-Z; cleared 0 = nothing).
      float occluder = perspective ? near * far / (d * (far - near) + near)
                                   : near + (1.0 - d) * (far - near);
      lit += (d <= 0.0 || receiver - bias <= occluder) ? 1.0 : 0.0;
    }
  return lit / 9.0;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  vec2 uv = (vec2(p) + 0.5) * frame.viewport.zw;
  float depth = texelFetch(gDepth, p, 0).r;
  vec3 viewDirWorld = safeNormalize(mat3(frame.invView) * viewPositionFromDepth(frame.invProj, uv, 0.5), vec3(0, 0, -1));

  if (isSky(depth)) {
    vec3 sky = frame.skyHorizon.w > 1.5
                   ? textureLod(environmentMap, equirectUV(viewDirWorld), 0.0).rgb * frame.skyZenith.w
                   : environmentRadiance(frame, viewDirWorld);
    imageStore(outLit, p, vec4(sky, 1.0));
    return;
  }
  vec3 pos = viewPositionFromDepth(frame.invProj, uv, depth);
  vec3 n = safeNormalize(texelFetch(gNormal, p, 0).xyz, vec3(0, 0, 1));
  vec3 albedo = texelFetch(gAlbedo, p, 0).rgb;
  vec2 rm = texelFetch(gMaterial, p, 0).rg;
  vec3 emission = texelFetch(gEmission, p, 0).rgb;
  float roughness = max(rm.x, 0.03), metallic = rm.y;
  vec3 v = safeNormalize(-pos, vec3(0, 0, 1));
  vec3 diffuseColor = albedo * (1.0 - metallic);
  vec3 f0 = mix(vec3(0.04), albedo, metallic);
  float shininess = clamp(2.0 / (roughness * roughness * roughness * roughness) - 2.0, 1.0, 4096.0);

  vec3 color = emission;
  int lightCount = int(frame.params.y);
  for (int i = 0; i < lightCount; ++i) {
    Light light = lights[i];
    int type = int(light.directionType.w);
    vec3 l;
    float attenuation = 1.0;
    if (type == 0) {
      l = safeNormalize(-light.directionType.xyz, vec3(0, 1, 0));
    } else {
      vec3 toLight = light.positionRange.xyz - pos;
      float d2 = max(dot(toLight, toLight), kMinLightDistance2);
      l = toLight * inversesqrt(d2);
      attenuation = 1.0 / d2;
      float range = light.positionRange.w;
      if (range > 0.0) {  // glTF's recommended smooth range window
        float r = d2 / (range * range);
        attenuation *= clamp(1.0 - r * r, 0.0, 1.0);
      }
      if (type == 2) {
        float cd = dot(safeNormalize(light.directionType.xyz, vec3(0, -1, 0)), -l);
        attenuation *= smoothstep(light.cone.y, max(light.cone.x, light.cone.y + 1e-4), cd);
      }
    }
    float ndl = max(dot(n, l), 0.0);
    if (ndl <= 0.0) continue;
    float visibility = shadowFactor(light, pos, ndl);
    if (visibility <= 0.0) continue;
    vec3 h = safeNormalize(l + v, n);
    float spec = (shininess + 8.0) / (8.0 * PI) * pow(max(dot(n, h), 0.0), shininess);
    vec3 brdf = diffuseColor / PI + f0 * spec;
    color += brdf * light.radiance.rgb * attenuation * ndl * visibility;
  }
  vec3 nWorld = mat3(frame.invView) * n;
  float ao = clamp(texture(aoTexture, uv).r, 0.0, 1.0);
  color += diffuseColor * environmentIrradianceOverPi(frame, nWorld) * ao;
  imageStore(outLit, p, vec4(color, 1.0));
}
