#version 460
#extension GL_GOOGLE_include_directive : require

#include "one_pass_filter.glsl"
