#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// transfer = radiance: filter along y and divide: sums -> "ambient" (obscurance_filter.glsl).
#define GI_AXIS ivec2(0, 1)
#define GI_RESOLVE 1
#define GI_AMBIENT 1
#include "obscurance_filter.glsl"
