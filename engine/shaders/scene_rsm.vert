#version 460
// Reflective shadow map (GpuScene::drawRsm): world position, normal and reflected flux.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "scene_view.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(set = 0, binding = 0, std430) readonly buffer Instances { Instance instances[]; };
layout(set = 0, binding = 1) uniform View { DrawView drawView; };
layout(push_constant) uniform Push { uint instance; } pc;

layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outWorldNormal;
layout(location = 2) out vec2 outUV;
layout(location = 3) flat out uint outMaterial;

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[1];
};

void main() {
  Instance inst = instances[pc.instance];
  vec3 world = (inst.model * vec4(inPosition, 1.0)).xyz;
  outWorldPos = world;
  outWorldNormal = mat3(inst.normalMatrix) * inNormal;
  outUV = inUV;
  outMaterial = inst.material.x;
  float clipDistance;
  gl_Position = projectWorld(drawView, world, clipDistance);
  gl_ClipDistance[0] = clipDistance;
}
