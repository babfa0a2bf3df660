#version 460
#extension GL_GOOGLE_include_directive : require

// The depth-aware blur along y: writes the final value.
#define GI_BLUR_AXIS 1
layout(set = 0, binding = 1, r16f) uniform writeonly image2D outValue;
#include "depth_aware_blur_pass.glsl"
