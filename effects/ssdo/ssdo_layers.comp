#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Depth layers 3 and 4 (`layers` 3..4; layer 0 is the G-buffer's, layer 1 rides in the surface
// texel): their 1 / view distance as two half floats in one R32UI texel, so the blocker test of
// the second solid interval [layer 2, layer 3] costs one 32-bit fetch per tap (ssdo.comp).
// Half floats: 2^-11 relative, as layer 1's. Guards: no fragment there (sky 0), a degenerate
// projection or beyond the half range read 0 (no layer); layer 3 only behind an existing layer 2.
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int kLayers = 3;  // 3: layer 2 only, 4: layers 2 and 3

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D gLayer2;
layout(set = 0, binding = 2) uniform sampler2D gLayer3;  // bound to gLayer2 with 3 layers
layout(set = 0, binding = 3, r32ui) uniform writeonly uimage2D outLayers;

float inverseDistance(float d, float p22, float p32) {
  float iz = abs(p32) > 1e-30 ? (d + p22) / p32 : 0.0;
  return d > 0.0 && iz > 0.0 && iz < 65000.0 ? iz : 0.0;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  float p22 = frame.proj[2][2], p32 = frame.proj[3][2];
  float iz2 = inverseDistance(texelFetch(gLayer2, p, 0).r, p22, p32);
  float iz3 = kLayers > 3 && iz2 > 0.0 ? inverseDistance(texelFetch(gLayer3, p, 0).r, p22, p32)
                                       : 0.0;
  imageStore(outLayers, p, uvec4(packHalf2x16(vec2(iz2, iz3)), 0u, 0u, 0u));
}
