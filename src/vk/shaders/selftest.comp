// dst[i] = msm_saturate(src[i]): proves that a shader compiles against the shared GLSL/C++ headers
// (include/msm/shared.h) and computes what their C++ build computes.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/shared.h"
#include "vk_bindings.h"

layout(local_size_x = 64) in;

layout(binding = MSM_BINDING_SELFTEST_SOURCE) readonly buffer Source { float src[]; };
layout(binding = MSM_BINDING_SELFTEST_DESTINATION) writeonly buffer Destination { float dst[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < pc.count) dst[i] = msm_saturate(src[i]);
}
