#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_PREFIX_FORMAT0 rgba16
#include "prefix_sums.glsl"
