#version 460
#extension GL_GOOGLE_include_directive : require
#define ISM_CLASSIC 1
#include "ism_irsm.glsl"
