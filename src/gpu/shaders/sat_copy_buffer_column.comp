#version 460
#extension GL_GOOGLE_include_directive : require
#define SAT_COPY_BUFFER
#define SAT_COPY_COLUMN
#include "sat_copy.glsl"
