#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_NL32 1
#include "shading_nonlinear.glsl"
