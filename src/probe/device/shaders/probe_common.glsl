// Shared by the light-probe shaders (probe_*.comp): the push constants of msm::probe::DeviceProbe
// (probe_interface.h, with the bindings) and the layout of the fixed-point tables.
#ifndef PROBE_COMMON_GLSL
#define PROBE_COMMON_GLSL
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "msm/light_probe.h"
#include "probe_interface.h"

layout(push_constant) uniform PushBlock { ProbePush pc; };

// Table k (0..6, msm_probe_texel's order) of a face: m² uint64 of inclusive sums, row-major;
// entry (x, y) sums texels [0, x] x [0, y].
uint probe_table_index(int face, int k, int x, int y) {
  return (uint(face * 7 + k) * uint(pc.size) + uint(y)) * uint(pc.size) + uint(x);
}
#endif
