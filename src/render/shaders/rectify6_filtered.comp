#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_FILTERED_MAP 1
#define MSM_SIX_MOMENTS 1
#include "rectify.glsl"
