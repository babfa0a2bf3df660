#version 460
#extension GL_GOOGLE_include_directive : require
// FrameUniforms (matrices, viewport, ...) and helpers shared with the engine's shaders.
#include "common.glsl"

// Desaturates the lit colour: mix(colour, luminance, strength).
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D litColor;                   // input
layout(set = 0, binding = 2, rgba16f) uniform writeonly image2D outColor;  // output
// Uniform-only settings travel as push constants: changing them needs no new pipeline.
layout(push_constant) uniform Params { float strength; } params;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
  vec4 c = texelFetch(litColor, p, 0);
  float luminance = dot(c.rgb, vec3(0.2126, 0.7152, 0.0722));
  imageStore(outColor, p, vec4(mix(c.rgb, vec3(luminance), params.strength), c.a));
}
