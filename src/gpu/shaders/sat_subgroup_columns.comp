#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_SAT_TABLE_FORMAT rgba32ui
#include "sat_subgroup_columns.glsl"
