#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// Filter along x: sums -> sums (obscurance_filter.glsl).
#define GI_AXIS ivec2(1, 0)
#define GI_RESOLVE 0
#define GI_AMBIENT 0
#include "obscurance_filter.glsl"
