#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The SSDO blur along y without the bounce: `ambient` only, no G-buffer read
// (ssdo_resolve.glsl).
#include "ssdo_resolve.glsl"
