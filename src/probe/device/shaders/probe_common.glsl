// Shared by the light-probe shaders (probe_*.comp): the push constants of msm::probe::DeviceProbe
// (ProbePush in device_probe.cpp, 48 bytes) and the layout of the fixed-point tables.
#ifndef PROBE_COMMON_GLSL
#define PROBE_COMMON_GLSL
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "msm/light_probe.h"

layout(push_constant) uniform Push {
  ivec2 panorama;     // width, height of the equirectangular panorama
  int size;           // m: texels per cube face side
  int supersampling;  // ss² bilinear samples per cube texel
  vec2 cos_sin;       // of the probe's rotation about +Y
  float scale;        // the tables' fixed-point scale (msm::probe::table_scale)
  float inv_scale;
  int count;          // regions of the cut
  int horizon_split;  // 1: the cut starts from ten regions (msm_first_region)
  int pad1, pad2;
} pc;

// Table k (0..6, msm_probe_texel's order) of a face: m² uint64 of inclusive sums, row-major;
// entry (x, y) sums texels [0, x] x [0, y].
uint probe_table_index(int face, int k, int x, int y) {
  return (uint(face * 7 + k) * uint(pc.size) + uint(y)) * uint(pc.size) + uint(x);
}
#endif
