#version 460
// Debug view "ism_atlas" in classic mode: the depth of the accurate paraboloid shadow maps.
// Runs only when the atlas is viewed (the frame graph culls it otherwise).
layout(local_size_x = 32, local_size_y = 16) in;
layout(set = 0, binding = 0) uniform sampler2D atlas;
layout(set = 0, binding = 1, r32f) uniform writeonly image2D view;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(view)))) return;
  imageStore(view, p, vec4(texelFetch(atlas, p, 0).r));
}
