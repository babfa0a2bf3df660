// Unit normals in 32 bits: the octahedral map of the sphere onto [-1, 1]^2, two 16-bit snorms
// (angle error < 0.004 deg). The G-buffer's normal (gbuffer.glsl) and any effect that packs a
// normal into a texel use it; gi/gbuffer.h holds the same code for the CPU.
#ifndef GI_NORMAL_CODEC_GLSL
#define GI_NORMAL_CODEC_GLSL

vec2 giOctWrap(vec2 v) {
  return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

// Guard: a zero or non-finite normal encodes as +z (the decoder never sees a zero vector).
uint giEncodeNormal(vec3 n) {
  float l1 = abs(n.x) + abs(n.y) + abs(n.z);
  if (!(l1 > 1e-30) || isinf(l1)) return packSnorm2x16(vec2(0.0));
  vec3 p = n / l1;
  vec2 e = p.z >= 0.0 ? p.xy : giOctWrap(p.xy);
  return packSnorm2x16(e);
}

vec3 giDecodeNormal(uint bits) {
  vec2 e = unpackSnorm2x16(bits);
  vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
  if (n.z < 0.0) n.xy = giOctWrap(n.xy);
  return normalize(n);  // |n|_1 = 1: never zero
}

#endif
