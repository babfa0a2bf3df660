#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Darkens the lit colour towards the corners: 1 inside `radius`, falling smoothly to
// 1 - strength at the corners (distance measured in aspect-corrected units).
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D litColor;
layout(set = 0, binding = 2, rgba16f) uniform writeonly image2D outColor;
layout(push_constant) uniform Params {
  float strength;
  float radius;
} params;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
  vec2 aspect = vec2(frame.viewport.x * frame.viewport.w, 1.0);
  vec2 d = ((vec2(p) + 0.5) * frame.viewport.zw - 0.5) * aspect;
  float r = length(d) / length(0.5 * aspect);  // 0 at the centre, 1 in the corners
  float falloff = smoothstep(params.radius, 1.0, r);
  vec4 c = texelFetch(litColor, p, 0);
  imageStore(outColor, p, vec4(c.rgb * (1.0 - params.strength * falloff), c.a));
}
