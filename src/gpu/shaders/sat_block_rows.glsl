// Summed-area table, block scheme (JCGT Appendix C), pass 1: workgroups of 8 × 8 threads, eight
// threads per row. The group walks its eight rows from left to right one 8 × 8 block at a time;
// every thread reads all eight texels of its row in the block and keeps the row's running sum, but
// writes only the prefix sum at its own column of the block: eight times the reads and additions,
// eight times the parallelism, and coalesced writes (eight neighbouring texels per row).
// Included by sat_block_rows.comp (RGBA32_UINT tables) and sat_block_rows_rg.comp (RG32_UINT tables, for RG moments).
#include "sat_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = MSM_BINDING_SAT_ROWS_MOMENTS) uniform sampler2D moments;
layout(binding = MSM_BINDING_SAT_ROWS_TABLE, MSM_SAT_TABLE_FORMAT) uniform writeonly uimage2D table;

void main() {
  int column = int(gl_LocalInvocationID.x); // within the block
  int y = int(gl_WorkGroupID.x) * 8 + int(gl_LocalInvocationID.y);
  if (y >= pc.size.y) return; // no barriers below: whole rows may leave
  uvec4 running = uvec4(0u);   // sum of the row left of the block
  for (int x0 = 0; x0 < pc.size.x; x0 += 8) {
    uvec4 mine = uvec4(0u);
    uvec4 block = uvec4(0u);
    for (int k = 0; k < 8; ++k) {
      if (x0 + k < pc.size.x) block += sat_quantized_texel(moments, ivec2(x0 + k, y));
      if (k == column) mine = running + block;
    }
    running += block;
    if (x0 + column < pc.size.x) imageStore(table, ivec2(x0 + column, y), mine);
  }
}
