#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Instances { Instance instances[]; };
layout(push_constant) uniform Push { uint instance; } pc;

layout(location = 0) out vec3 outViewNormal;
layout(location = 1) out vec2 outUV;
layout(location = 2) out vec4 outClip;
layout(location = 3) out vec4 outPrevClip;
layout(location = 4) flat out uint outMaterial;
layout(location = 5) out vec3 outViewPos;

void main() {
  Instance inst = instances[pc.instance];
  vec4 world = inst.model * vec4(inPosition, 1.0);
  vec4 viewPos = frame.view * world;
  outViewPos = viewPos.xyz;
  outViewNormal = mat3(frame.view) * (mat3(inst.normalMatrix) * inNormal);
  outUV = inUV;
  outClip = frame.proj * viewPos;
  outPrevClip = frame.prevViewProj * (inst.prevModel * vec4(inPosition, 1.0));
  outMaterial = inst.material.x;
  gl_Position = outClip;
}
