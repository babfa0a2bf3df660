#version 460
// Debug view of the surface points (`gi-render --view points`): every point that lies on a
// visible surface (its depth within a small tolerance of the G-buffer's) is splatted as one
// pixel coloured by its world normal. Dispatch 0 clears, dispatch 1 splats.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 256) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 2) uniform sampler2D depthTex;
layout(set = 0, binding = 3, rgba16f) uniform writeonly image2D outImage;

layout(push_constant) uniform Push {
  uint count;
  uint clear;
} pc;

void main() {
  // The grid is 2-D when one row of workgroups would exceed 65535 (dispatch256).
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 256u;
  ivec2 size = imageSize(outImage);
  if (pc.clear != 0u) {
    if (i < uint(size.x * size.y)) imageStore(outImage, ivec2(i % uint(size.x), i / uint(size.x)), vec4(0.0, 0.0, 0.0, 1.0));
    return;
  }
  if (i >= pc.count) return;
  vec4 clip = frame.viewProj * vec4(points[2u * i].xyz, 1.0);
  if (!(clip.w > 0.0)) return;  // behind the camera
  vec3 ndc = clip.xyz / clip.w;
  ivec2 pixel = ivec2(floor((ndc.xy * 0.5 + 0.5) * vec2(size)));
  if (any(lessThan(pixel, ivec2(0))) || any(greaterThanEqual(pixel, size))) return;
  float surface = texelFetch(depthTex, pixel, 0).r;
  // Reverse-Z: a hidden point has a smaller depth than the visible surface.
  if (isSky(surface) || ndc.z < surface * 0.995) return;
  imageStore(outImage, pixel, vec4(points[2u * i + 1u].xyz * 0.5 + 0.5, 1.0));
}
