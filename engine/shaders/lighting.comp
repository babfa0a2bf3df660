#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Direct lighting from the G-buffer: Lambert + normalised Blinn-Phong for point, spot and
// directional lights, plus the environment's ambient term. Writes linear HDR radiance.
layout(local_size_x = 8, local_size_y = 8) in;

struct Light {
  vec4 positionRange;   // view-space position, range (0: infinite)
  vec4 directionType;   // view-space direction the light points to, type (0 dir, 1 point, 2 spot)
  vec4 radiance;        // colour * intensity
  vec4 cone;            // cos(inner), cos(outer)
};

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

const float PI = 3.14159265358979;
// Guard: squared light distance is clamped so a light on the surface stays finite.
const float kMinLightDistance2 = 1e-4;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  vec2 uv = (vec2(p) + 0.5) * frame.viewport.zw;
  float depth = texelFetch(gDepth, p, 0).r;
  vec3 viewDirWorld = safeNormalize(mat3(frame.invView) * viewPositionFromDepth(frame.invProj, uv, 0.5), vec3(0, 0, -1));

  if (isSky(depth)) {
    imageStore(outLit, p, vec4(environmentRadiance(frame, viewDirWorld), 1.0));
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
    vec3 h = safeNormalize(l + v, n);
    float spec = (shininess + 8.0) / (8.0 * PI) * pow(max(dot(n, h), 0.0), shininess);
    vec3 brdf = diffuseColor / PI + f0 * spec;
    color += brdf * light.radiance.rgb * attenuation * ndl;
  }
  vec3 nWorld = mat3(frame.invView) * n;
  float ao = clamp(texture(aoTexture, uv).r, 0.0, 1.0);
  color += diffuseColor * environmentIrradianceOverPi(frame, nWorld) * ao;
  imageStore(outLit, p, vec4(color, 1.0));
}
