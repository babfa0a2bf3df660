#version 460
#extension GL_GOOGLE_include_directive : require
// The Alchemy cross-bilateral filter along y, writing the final "ao": alchemy_blur.glsl.
const ivec2 kAxis = ivec2(0, 1);
#define ALCHEMY_BLUR_FINAL
#include "alchemy_blur.glsl"
