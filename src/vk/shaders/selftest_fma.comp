// dst[i] = msm_fma(a, b, c) for src[i] = (a, b, c, unused): shared.h's msm_fma on the device, with
// the specialization constant msm_fused_fma that create_program sets (the native fma() where the
// Context found it fused, else the exact emulation), against std::fma (vk_test.cpp).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/shared.h"
#include "vk_bindings.h"

layout(local_size_x = 64) in;

layout(std430, binding = MSM_BINDING_SELFTEST_SOURCE) readonly buffer Source { vec4 src[]; };
layout(std430, binding = MSM_BINDING_SELFTEST_DESTINATION) writeonly buffer Destination { float dst[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < pc.count) dst[i] = msm_fma(src[i].x, src[i].y, src[i].z);
}
