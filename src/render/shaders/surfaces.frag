// The surfaces pass of deferred shading: the visible surface of each pixel (position, normal towards
// the viewer, albedo and opacity), alpha-tested cut-outs discarded (shading.glsl, MSM_SURFACES).
#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_SURFACES 1
#include "shading.glsl"
