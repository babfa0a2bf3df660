#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The SSDO blur along y with the bounce: `ambient` and `indirect` (ssdo_resolve.glsl).
#define SSDO_RESOLVE_INDIRECT
#include "ssdo_resolve.glsl"
