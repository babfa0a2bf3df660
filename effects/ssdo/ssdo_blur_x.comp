#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The SSDO blur along x: keeps the packed texel for the y pass (ssdo_resolve.comp).
#define GI_BLUR_AXIS 0
#include "ssdo_blur.glsl"
layout(set = 0, binding = 3, rgba32ui) uniform writeonly uimage2D outRaw;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  uvec4 centre = texelFetch(inRaw, p, 0);
  vec3 direct, bounce;
  ssdoBlur(p, size, centre, direct, bounce);
  imageStore(outRaw, p,
             uvec4(packRgb9e5(direct), kBounceTerm ? packRgb9e5(bounce) : 0u, centre.zw));
}
