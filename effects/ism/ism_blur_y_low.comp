#version 460
#extension GL_GOOGLE_include_directive : require
#define AXIS 1
#define LOW 1
#include "ism_blur.glsl"
