#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_SIX_MOMENTS 1
#define MSM_PREFIX_FORMAT0 rgba16
#define MSM_PREFIX_FORMAT1 rg16
#include "prefix_sums.glsl"
