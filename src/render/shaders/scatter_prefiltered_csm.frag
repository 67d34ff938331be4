#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_SCATTER_PREFILTERED 1
#define MSM_CSM 1
#include "scatter.glsl"
