#version 460
// Clears the ISM atlas (mip 0) to "no point".
#extension GL_GOOGLE_include_directive : require
#include "ism_common.glsl"

layout(local_size_x = 32, local_size_y = 16) in;
layout(set = 0, binding = 0, r32ui) uniform writeonly uimage2D atlas;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (all(lessThan(p, imageSize(atlas)))) imageStore(atlas, p, uvec4(ISM_EMPTY));
}
