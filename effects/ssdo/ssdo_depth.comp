#version 460
#extension GL_GOOGLE_include_directive : require
// Directional occlusion alone (ssdo.glsl, SSDO_DEPTH_INPUT): taps read the G-buffer depth.
#define SSDO_DEPTH_INPUT 1
#include "ssdo.glsl"
