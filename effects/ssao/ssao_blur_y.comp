#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The SSAO blur along y: writes the final AO.
#define GI_BLUR_AXIS 1
layout(set = 0, binding = 3, r16f) uniform writeonly image2D outAO;
#include "ssao_blur.glsl"
