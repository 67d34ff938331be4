// Summed-area table, subgroup scheme, pass 1: one subgroup per row walks it in chunks of as many
// neighbouring texels as the subgroup has lanes (coalesced loads and stores on a GPU). The chunk's
// inclusive prefix sums come from subgroupInclusiveAdd on the uvec4 (wrapping modulo 2^32, as the
// CPU's sums), plus the running carry of the chunks before it; the carry then grows by the chunk's
// total, the last lane's sum (subgroupShuffle). No barriers, no shared memory. Pass 2 is
// sat_columns.glsl, whose neighbouring threads already walk neighbouring columns.
// Correct for any subgroup size and partial subgroups: the chunk width is the number of active
// lanes and a lane's place in the chunk its rank among them; rows are spread over the subgroups of
// the whole dispatch (a grid-stride loop), so the host's group count only has to be about right.
// Included by sat_subgroup_rows.comp (RGBA32_UINT tables) and sat_subgroup_rows_rg.comp (RG32_UINT).
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#include "sat_common.glsl"

layout(local_size_x = 64) in;
layout(binding = MSM_BINDING_SAT_ROWS_MOMENTS) uniform sampler2D moments;
layout(binding = MSM_BINDING_SAT_ROWS_TABLE, MSM_SAT_TABLE_FORMAT) uniform writeonly uimage2D table;

uvec4 sat_scan_load(ivec2 p) { return sat_quantized_texel(moments, p); }
#define SAT_ALONG_ROWS
#define SAT_SUBGROUP
#include "sat_scan_lines.glsl"
