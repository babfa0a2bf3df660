#version 460
#extension GL_GOOGLE_include_directive : require
// The Alchemy cross-bilateral filter along x: alchemy_blur.glsl.
const ivec2 kAxis = ivec2(1, 0);
#include "alchemy_blur.glsl"
