#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The SSAO blur along x: keeps the packed texel (ao, 1/z, slopes) for the y pass.
#define GI_BLUR_AXIS 0
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D outAO;
#include "ssao_blur.glsl"
