#version 460
// Fixed-point probe tables, pass 2: one invocation per column of one table of a face adds the
// column's running sums in place (integers: any order gives the CPU's sums).
#extension GL_GOOGLE_include_directive : require
#include "probe_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_PROBE_COLUMNS_TABLES, std430) buffer Tables { uint64_t tables[]; };

void main() {
  int x = int(gl_GlobalInvocationID.x), k = int(gl_GlobalInvocationID.y), face = int(gl_GlobalInvocationID.z);
  if (x >= pc.size) return;
  uint64_t sum = 0ul;
  for (int y = 0; y < pc.size; ++y) {
    uint i = probe_table_index(face, k, x, y);
    sum += tables[i];
    tables[i] = sum;
  }
}
