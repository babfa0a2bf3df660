#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The cost floor: one G-buffer read and one 8-bit write per pixel. Later effects report their
// time as a ratio to this pass measured in the same run.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform usampler2D gPacked;  // the packed G-buffer
layout(set = 0, binding = 2, rgba8) uniform writeonly image2D outFloor;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
  // The texel's bits as they are (decoding is the readers' work, not the floor's).
  imageStore(outFloor, p, unpackUnorm4x8(texelFetch(gPacked, p, 0).y));
}
