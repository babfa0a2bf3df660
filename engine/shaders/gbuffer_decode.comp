#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// One channel of the packed G-buffer unpacked to RGBA32F (the views and read-backs "normal",
// "albedo", "material", "emission"; gi/gbuffer.h). Runs only when that channel is asked for.
layout(local_size_x = 32, local_size_y = 16) in;
layout(constant_id = 0) const int kChannel = 0;  // gi::gbuffer::kChannels order

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
#define GI_GBUFFER_BINDING 1
#include "gbuffer.glsl"
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D outChannel;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
  uvec4 g = giGBufferLoad(p);
  float geometry = giGBufferIsGeometry(g) ? 1.0 : 0.0;
  vec4 v;
  if (kChannel == 0)
    v = geometry > 0.0 ? vec4(giGBufferNormal(g), 1.0) : vec4(0.0);
  else if (kChannel == 1)
    v = vec4(giGBufferAlbedo(g), geometry);
  else if (kChannel == 2)
    v = vec4(giGBufferRoughness(g), giGBufferMetallic(g), 0.0, geometry);
  else
    v = vec4(giGBufferEmission(g), geometry);
  imageStore(outChannel, p, v);
}
