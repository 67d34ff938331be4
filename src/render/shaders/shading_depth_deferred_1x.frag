// shading_depth_deferred.frag for a single-sample depth map.
#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_DEFERRED_SHADOWS 1
#define MSM_SINGLE_SAMPLE 1
#include "shading_depth.glsl"
