#version 460
// Depth-only rendering of mesh instances into a shadow map (or one cube face of a point
// light's 3x2 atlas). Reverse-Z like the G-buffer: depth 1 at the light's near plane.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) in vec3 inPosition;

layout(set = 0, binding = 0, std430) readonly buffer Instances { Instance instances[]; };
layout(push_constant) uniform Push {
  mat4 viewProj;  // world -> light clip space
  uint instance;
} pc;

void main() {
  gl_Position = pc.viewProj * (instances[pc.instance].model * vec4(inPosition, 1.0));
}
