// Summed-area table, scan scheme, pass 1: one workgroup of 64 threads per row walks it in chunks
// of 64 texels. Each thread fetches one texel of the chunk (neighbouring threads, neighbouring
// texels: coalesced on a GPU, where the one-thread-per-row pass gathers a row pitch apart), the
// chunk's inclusive prefix sums come from a Hillis-Steele scan in shared memory (6 steps), plus
// the total of the chunks before it. Every texel is read and written once; pass 2 is
// sat_columns.glsl, whose neighbouring threads already walk neighbouring columns.
// Included by sat_scan_rows.comp (RGBA32_UINT tables) and sat_scan_rows_rg.comp (RG32_UINT).
#include "sat_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_SAT_ROWS_MOMENTS) uniform sampler2D moments;
layout(binding = MSM_BINDING_SAT_ROWS_TABLE, MSM_SAT_TABLE_FORMAT) uniform writeonly uimage2D table;

shared uvec4 chunk[64];

void main() {
  int y = int(gl_WorkGroupID.x), t = int(gl_LocalInvocationID.x);
  uvec4 carry = uvec4(0u); // wraps modulo 2^32, as the CPU's sums
  for (int x0 = 0; x0 < pc.size.x; x0 += 64) {
    int x = x0 + t;
    uvec4 v = x < pc.size.x ? sat_quantized_texel(moments, ivec2(x, y)) : uvec4(0u);
    chunk[t] = v;
    barrier();
    for (int d = 1; d < 64; d *= 2) {
      uvec4 add = t >= d ? chunk[t - d] : uvec4(0u);
      barrier();
      v += add;
      chunk[t] = v;
      barrier();
    }
    if (x < pc.size.x) imageStore(table, ivec2(x, y), carry + v);
    carry += chunk[63];
    barrier(); // before the next chunk overwrites it
  }
}
