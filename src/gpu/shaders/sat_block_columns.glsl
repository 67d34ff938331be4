// Summed-area table, block scheme (JCGT Appendix C), pass 2: the same walk down the columns of the
// row sums, in place: workgroups of 8 × 8 threads, eight per column, each reading all eight texels
// of its column in the block and writing the prefix sum at its own row of the block. In place, a
// block is overwritten only after every thread of the group has read it (image memory barrier +
// execution barrier); later blocks read other texels.
// Included by sat_block_columns.comp (RGBA32_UINT tables) and sat_block_columns_rg.comp (RG32_UINT tables, for RG moments).
#include "sat_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = MSM_BINDING_SAT_COLUMNS_TABLE, MSM_SAT_TABLE_FORMAT) uniform uimage2D table;

void main() {
  int x = int(gl_WorkGroupID.x) * 8 + int(gl_LocalInvocationID.x);
  int row = int(gl_LocalInvocationID.y); // within the block
  bool inside = x < pc.size.x;           // every thread stays for the barriers
  uvec4 running = uvec4(0u);             // sum of the column above the block
  for (int y0 = 0; y0 < pc.size.y; y0 += 8) {
    uvec4 mine = uvec4(0u);
    uvec4 block = uvec4(0u);
    for (int k = 0; k < 8; ++k) {
      if (inside && y0 + k < pc.size.y) block += imageLoad(table, ivec2(x, y0 + k));
      if (k == row) mine = running + block;
    }
    running += block;
    memoryBarrierImage();
    barrier();
    if (inside && y0 + row < pc.size.y) imageStore(table, ivec2(x, y0 + row), mine);
  }
}
