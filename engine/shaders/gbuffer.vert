#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Instances { Instance instances[]; };
struct Material {
  vec4 baseColor;
  vec4 emission;  // rgb
  vec4 params;    // roughness, metallic, texture index (-1 none), unused
};
layout(set = 0, binding = 2, std430) readonly buffer Materials { Material materials[]; };
// Per draw (DrawPush in engine/src/render/scene_gpu.cpp): what every vertex needs comes as push constants, one
// read for all lanes; only the previous model matrix is read from the instance buffer.
layout(push_constant) uniform Push {
  mat4 model;
  mat3 normalMatrix;
  uint instance;
  uint material;
} pc;

layout(location = 0) out vec3 outViewNormal;
layout(location = 1) out vec2 outUV;
layout(location = 2) out vec4 outClip;
layout(location = 3) out vec4 outPrevClip;
layout(location = 4) out vec3 outViewPos;
// The draw's material, read here once per vertex: a per-fragment read of the material buffer
// (an index llvmpipe cannot know to be uniform, so one load per lane) cost 2/3 of the pass.
layout(location = 5) flat out vec4 outBaseColor;
layout(location = 6) flat out vec4 outEmission;   // rgb
layout(location = 7) flat out vec4 outParams;     // clamped roughness, metallic; textured (1/0)

void main() {
  vec4 world = pc.model * vec4(inPosition, 1.0);
  vec4 viewPos = frame.view * world;
  outViewPos = viewPos.xyz;
  outViewNormal = mat3(frame.view) * (pc.normalMatrix * inNormal);
  outUV = inUV;
  outClip = frame.proj * viewPos;
  outPrevClip = frame.prevViewProj * (instances[pc.instance].prevModel * vec4(inPosition, 1.0));
  Material m = materials[pc.material];
  outBaseColor = m.baseColor;
  outEmission = vec4(m.emission.rgb, 1.0);
  outParams = vec4(clamp(m.params.x, 0.0, 1.0), clamp(m.params.y, 0.0, 1.0), m.params.z >= 0.0 ? 1.0 : 0.0, 1.0);
  gl_Position = outClip;
}
