#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_SIX_MOMENTS 1
#define MSM_PREFIX_ODD_EVEN 1
#define MSM_PREFIX_FORMAT0 rgb10_a2
#define MSM_PREFIX_FORMAT1 rgb10_a2
#include "prefix_sums.glsl"
