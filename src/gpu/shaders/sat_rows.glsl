// Summed-area table, simple scheme, pass 1 (JCGT §4.2 after Klehm et al. 2014): one thread per
// row writes the row's running sums of the quantized moments (uint, wrapping modulo 2^32).
// Included by sat_rows.comp (RGBA32_UINT tables) and sat_rows_rg.comp (RG32_UINT tables, for RG moments).
#include "sat_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_SAT_ROWS_MOMENTS) uniform sampler2D moments;
layout(binding = MSM_BINDING_SAT_ROWS_TABLE, MSM_SAT_TABLE_FORMAT) uniform writeonly uimage2D table;

uvec4 sat_scan_load(ivec2 p) { return sat_quantized_texel(moments, p); }
#define SAT_ALONG_ROWS
#include "sat_scan_lines.glsl"
