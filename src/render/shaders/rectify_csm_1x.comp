#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_CSM 1
#define MSM_SINGLE_SAMPLE 1
#include "rectify.glsl"
