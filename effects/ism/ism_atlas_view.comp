#version 460
// Debug view "ism_atlas" of the imperfect shadow maps: distances in world units (the r32ui
// atlas holds them as float bits, written by atomic min); 0 = a hole no point reached and
// pull-push did not fill. Runs only when the atlas is viewed (the frame graph culls it
// otherwise).
#extension GL_GOOGLE_include_directive : require
#include "ism_common.glsl"

layout(local_size_x = 32, local_size_y = 16) in;
layout(set = 0, binding = 0) uniform usampler2D atlas;
layout(set = 0, binding = 1, r32f) uniform writeonly image2D view;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(view)))) return;
  uint t = texelFetch(atlas, p, 0).r;
  imageStore(view, p, vec4(t == ISM_EMPTY ? 0.0 : uintBitsToFloat(t)));
}
