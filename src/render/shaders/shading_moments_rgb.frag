// Coloured translucent shadows: one set of moment images per colour channel (JCGT §3).
#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_COLOURED_SHADOWS 1
#include "shading_moments.glsl"
