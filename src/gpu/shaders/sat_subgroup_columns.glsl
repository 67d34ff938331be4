// Summed-area table, subgroup scheme, pass 2 (the variant of SatBuilder::Scheme::subgroup_rows_and_columns):
// one subgroup per column turns the row sums of pass 1 into the table in place, walking down in
// chunks of as many texels as the subgroup has active lanes, with subgroupInclusiveAdd and a carry
// as sat_subgroup_rows.glsl does along rows. Its lanes touch texels a row pitch apart (no
// coalescing on a GPU, unlike sat_columns.glsl, whose neighbouring threads walk neighbouring
// columns): kept to measure both on a CPU device, where lanes are SIMD lanes of one thread.
// Included by sat_subgroup_columns.comp (RGBA32_UINT tables) and sat_subgroup_columns_rg.comp (RG32_UINT).
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#include "sat_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_SAT_COLUMNS_TABLE, MSM_SAT_TABLE_FORMAT) uniform uimage2D table;

uvec4 sat_scan_load(ivec2 p) { return imageLoad(table, p); }
#define SAT_SUBGROUP
#include "sat_scan_lines.glsl"
