#version 460
#extension GL_GOOGLE_include_directive : require

// The depth-aware blur along x: keeps the packed texel (value, 1/z, slopes) for the y pass.
#define GI_BLUR_AXIS 0
#define GI_BLUR_KEEP_PACKED
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D outValue;
#include "depth_aware_blur_pass.glsl"
