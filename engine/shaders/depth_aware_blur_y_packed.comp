#version 460
#extension GL_GOOGLE_include_directive : require

// The depth-aware blur along y at a reduced resolution: keeps the packed texel (value, 1/z,
// slopes) for the upsample (depth_aware_upsample.comp).
#define GI_BLUR_AXIS 1
#define GI_BLUR_KEEP_PACKED
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D outValue;
#include "depth_aware_blur_pass.glsl"
