#version 460
// Reflective shadow map (GpuScene::drawRsm): world position, normal and reflected flux.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "scene_view.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(set = 0, binding = 0) uniform View { DrawView drawView; };
// Per draw, as gbuffer.vert (DrawPush in scene_gpu.cpp).
layout(push_constant) uniform Push {
  mat4 model;
  mat3 normalMatrix;
  uint instance;
} pc;

layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outWorldNormal;
layout(location = 2) out vec2 outUV;

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[1];
};

void main() {
  vec3 world = (pc.model * vec4(inPosition, 1.0)).xyz;
  outWorldPos = world;
  outWorldNormal = pc.normalMatrix * inNormal;
  outUV = inUV;
  float clipDistance;
  gl_Position = projectWorld(drawView, world, clipDistance);
  gl_ClipDistance[0] = clipDistance;
}
