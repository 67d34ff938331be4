#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_SIX_MOMENTS 1
#define MSM_PREFIX_FORMAT0 rgba32f
#define MSM_PREFIX_FORMAT1 rg32f
#include "prefix_sums.glsl"
