#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Instances { Instance instances[]; };
// Per draw (DrawPush in engine/src/render/scene_gpu.cpp): what every vertex needs comes as push
// constants, one read for all lanes; only the previous model matrix is read from the instances.
layout(push_constant) uniform Push {
  mat4 model;
  mat3 normalMatrix;
  uint instance;
} pc;

// Few varyings: on llvmpipe the per-triangle set-up cost grows with them, and for small
// triangles (a 70k-triangle model) that set-up is most of the pass. The material is a uniform
// block of the fragment shader, the current clip position comes from gl_FragCoord.
layout(location = 0) out vec3 outViewNormal;
layout(location = 1) out vec2 outUV;
layout(location = 2) out vec4 outPrevClip;
layout(location = 3) out vec3 outViewPos;

void main() {
  vec4 world = pc.model * vec4(inPosition, 1.0);
  vec4 viewPos = frame.view * world;
  outViewPos = viewPos.xyz;
  outViewNormal = mat3(frame.view) * (pc.normalMatrix * inNormal);
  outUV = inUV;
  outPrevClip = frame.prevViewProj * (instances[pc.instance].prevModel * vec4(inPosition, 1.0));
  gl_Position = frame.proj * viewPos;
}
