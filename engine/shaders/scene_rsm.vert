#version 460
// Reflective shadow map (GpuScene::drawRsm): world position, normal and reflected flux.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "scene_view.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(set = 0, binding = 1) uniform View { DrawView drawView; };
struct Material {
  vec4 baseColor;
  vec4 emission;
  vec4 params;  // roughness, metallic, texture index (-1 none), unused
};
layout(set = 0, binding = 2, std430) readonly buffer Materials { Material materials[]; };
// Per draw, as gbuffer.vert (DrawPush in scene_gpu.cpp).
layout(push_constant) uniform Push {
  mat4 model;
  mat3 normalMatrix;
  uint instance;
  uint material;
} pc;

layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outWorldNormal;
layout(location = 2) out vec2 outUV;
// The draw's material, read once per vertex (per fragment it is one load per lane on llvmpipe).
layout(location = 3) flat out vec4 outBaseColor;  // a: textured (1/0)

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[1];
};

void main() {
  vec3 world = (pc.model * vec4(inPosition, 1.0)).xyz;
  outWorldPos = world;
  outWorldNormal = pc.normalMatrix * inNormal;
  outUV = inUV;
  Material m = materials[pc.material];
  outBaseColor = vec4(m.baseColor.rgb, m.params.z >= 0.0 ? 1.0 : 0.0);
  float clipDistance;
  gl_Position = projectWorld(drawView, world, clipDistance);
  gl_ClipDistance[0] = clipDistance;
}
