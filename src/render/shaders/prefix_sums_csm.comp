#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_CSM 1
#define MSM_PREFIX_FORMAT0 rgba8
#include "prefix_sums.glsl"
