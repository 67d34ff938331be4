// Summed-area table, simple scheme, pass 1 (JCGT §4.2 after Klehm et al. 2014): one thread per
// row writes the row's running sums of the quantized moments (uint, wrapping modulo 2^32).
// Included by sat_rows.comp (RGBA32_UINT tables) and sat_rows_rg.comp (RG32_UINT tables, for RG moments).
#include "sat_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_SAT_ROWS_MOMENTS) uniform sampler2D moments;
layout(binding = MSM_BINDING_SAT_ROWS_TABLE, MSM_SAT_TABLE_FORMAT) uniform writeonly uimage2D table;

void main() {
  int y = int(gl_GlobalInvocationID.x);
  if (y >= pc.size.y) return;
  uvec4 sum = uvec4(0u);
  for (int x = 0; x < pc.size.x; ++x) {
    sum += sat_quantized_texel(moments, ivec2(x, y));
    imageStore(table, ivec2(x, y), sum);
  }
}
