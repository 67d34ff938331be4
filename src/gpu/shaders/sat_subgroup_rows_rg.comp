// The table of two-channel moments: RG32_UINT (half the memory and traffic of RGBA32_UINT).
#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_SAT_TABLE_FORMAT rg32ui
#include "sat_subgroup_rows.glsl"
