#version 460
#extension GL_GOOGLE_include_directive : require
#define SAT_COPY_IMAGE
#define SAT_COPY_ROW
#include "sat_copy.glsl"
