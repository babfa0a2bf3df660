#version 460
// Depth-only draw of mesh instances from one DrawView (GpuScene::drawDepth): shadow maps,
// extra cameras, cube faces and paraboloid hemispheres. Reverse-Z like the G-buffer.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "scene_view.glsl"

layout(location = 0) in vec3 inPosition;

layout(set = 0, binding = 0) uniform View { DrawView drawView; };
// The instance's model matrix as a push constant (DrawPush in scene_gpu.cpp): a per-vertex
// read of the instance buffer costs one load per lane on llvmpipe.
layout(push_constant) uniform Push { mat4 model; } pc;

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[1];
};

void main() {
  float clipDistance;
  // view * (model * p) in the order gbuffer.vert uses, so equal views give equal depth.
  gl_Position = projectWorld(drawView, (pc.model * vec4(inPosition, 1.0)).xyz, clipDistance);
  gl_ClipDistance[0] = clipDistance;
}
