// Whether this device's fma() is the fused multiply-add (one rounding): msm::vk::Context runs it
// once at creation on cases where a * b + c rounded once, rounded twice (a * b, then + c) and
// computed in double and then rounded to float all differ (context.cpp, probe_fused_fma), and compares
// with std::fma. Each case is evaluated twice, as msm_fma (shared.h) uses fma(): in plain code, and
// consumed by a `precise` variable (SPIR-V NoContraction), which a driver may lower differently.
// The inputs come from the buffer, so neither glslc nor the driver can fold them.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "vk_bindings.h"

layout(local_size_x = 64) in;

// Per case i of count = v.length() / 3: v[i] = (a, b, c, unused) and a copy of it in v[count + i]
// (separate loads, so that the optimizer cannot merge the two fma()), results (fma, precise fma,
// 0, 0) in v[2 count + i].
layout(std430, binding = MSM_BINDING_FMA_PROBE_CASES) buffer Cases { vec4 v[]; };

void main() {
  uint count = uint(v.length()) / 3u;
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec4 x = v[i], y = v[count + i];
  float plain = fma(x.x, x.y, x.z);
  precise float consumed = fma(y.x, y.y, y.z);
  v[2u * count + i] = vec4(plain, consumed, 0.0, 0.0);
}
