#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "guards.glsl"

// Exposure, ACES filmic curve (Narkowicz fit) and sRGB encoding into the 8-bit output.
layout(local_size_x = 32, local_size_y = 16) in;  // kScreenGroupX/Y (builtin_passes.h)
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D litColor;
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D outColor;

vec3 aces(vec3 x) {
  return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 linearToSrgb(vec3 c) {
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
  vec3 hdr = texelFetch(litColor, p, 0).rgb * frame.params.x;
  // Guard: a non-finite input pixel is shown as black rather than spreading NaN.
  if (giGuard(GI_GUARD_NONFINITE, any(isnan(hdr)) || any(isinf(hdr)))) hdr = vec3(0.0);
  imageStore(outColor, p, vec4(linearToSrgb(aces(max(hdr, 0.0))), 1.0));
}
