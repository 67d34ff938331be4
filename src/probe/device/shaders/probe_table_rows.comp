#version 460
// Fixed-point probe tables, pass 1: one invocation per row of a face writes the running sums of
// the row's seven texel values (msm_probe_texel, the CPU's ProbeTables code) as uint64.
#extension GL_GOOGLE_include_directive : require
#include "probe_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_PROBE_ROWS_CUBE, std430) readonly buffer Cube { vec4 cube[]; };
// m² texel weights (msm_cube_texel_weight), then m texel-centre coordinates, from the host.
layout(binding = MSM_BINDING_PROBE_ROWS_WEIGHTS, std430) readonly buffer Weights { float weights[]; };
layout(binding = MSM_BINDING_PROBE_ROWS_TABLES, std430) writeonly buffer Tables { uint64_t tables[]; };

void main() {
  int y = int(gl_GlobalInvocationID.x), face = int(gl_GlobalInvocationID.y), m = pc.size;
  if (y >= m) return;
  u64vec4 sa = u64vec4(0ul);
  u64vec3 sb = u64vec3(0ul);
  float v = weights[m * m + y];
  for (int x = 0; x < m; ++x) {
    MsmProbeTexel t = msm_probe_texel(cube[(face * m + y) * m + x].xyz, weights[y * m + x], weights[m * m + x], v,
                                      pc.scale);
    sa += u64vec4(t.a); // truncation, as the CPU's conversion
    sb += u64vec3(t.b);
    tables[probe_table_index(face, 0, x, y)] = sa.x;
    tables[probe_table_index(face, 1, x, y)] = sa.y;
    tables[probe_table_index(face, 2, x, y)] = sa.z;
    tables[probe_table_index(face, 3, x, y)] = sa.w;
    tables[probe_table_index(face, 4, x, y)] = sb.x;
    tables[probe_table_index(face, 5, x, y)] = sb.y;
    tables[probe_table_index(face, 6, x, y)] = sb.z;
  }
}
