// Deferred shading with the soft shadows (mssm4, mssm6, vssm, cssm8, cssm16): one evaluation per pixel of the
// surfaces pass (shading.glsl, MSM_DEFERRED_SHADOWS).
#version 460
#extension GL_GOOGLE_include_directive : require
#define MSM_DEFERRED_SHADOWS 1
#include "shading_soft.glsl"
