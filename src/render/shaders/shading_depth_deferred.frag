// Deferred shading with PCF, PCSS and the plain map: one shadow evaluation per pixel of the surfaces
// pass (shading.glsl, MSM_DEFERRED_SHADOWS).
#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_DEFERRED_SHADOWS 1
#include "shading_depth.glsl"
