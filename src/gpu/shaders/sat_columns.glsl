// Summed-area table, simple scheme, pass 2: one thread per column turns the row sums of pass 1
// into the table, in place (each thread reads and writes only its own column).
// Included by sat_columns.comp (RGBA32_UINT tables) and sat_columns_rg.comp (RG32_UINT tables, for RG moments).
#include "sat_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_SAT_COLUMNS_TABLE, MSM_SAT_TABLE_FORMAT) uniform uimage2D table;

uvec4 sat_scan_load(ivec2 p) { return imageLoad(table, p); }
#include "sat_scan_lines.glsl"
