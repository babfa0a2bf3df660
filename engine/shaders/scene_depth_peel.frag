#version 460
// Depth peeling (GpuScene::drawDepthPeeled): keep a fragment only when it lies strictly behind
// the previous depth layer at its pixel. Reverse-Z: behind = smaller depth. The relative margin
// (2^-20, ~16 float ulps) absorbs the rounding between the pipeline that drew the previous layer
// (e.g. the G-buffer's) and this one, so the previous layer's own surface never comes back; a
// sky pixel (0) keeps nothing.
layout(set = 0, binding = 1) uniform sampler2D previousDepth;

void main() {
  float previous = texelFetch(previousDepth, ivec2(gl_FragCoord.xy), 0).r;
  if (!(gl_FragCoord.z < previous * (1.0 - 1.0 / 1048576.0))) discard;
}
