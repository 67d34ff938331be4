#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_FILTERED_MAP 1
#define MSM_CSM 1
#include "rectify.glsl"
