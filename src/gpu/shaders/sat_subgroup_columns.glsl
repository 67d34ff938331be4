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

void main() {
  const int lanes = int(subgroupAdd(1u));
  const int rank = int(subgroupExclusiveAdd(1u));
  const uint last = subgroupMax(gl_SubgroupInvocationID);
  const int subgroups = int(gl_NumWorkGroups.x * gl_NumSubgroups);
  for (int x = int(gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID); x < pc.size.x; x += subgroups) {
    uvec4 carry = uvec4(0u);
    for (int y0 = 0; y0 < pc.size.y; y0 += lanes) {
      int y = y0 + rank;
      uvec4 v = y < pc.size.y ? imageLoad(table, ivec2(x, y)) : uvec4(0u);
      v = carry + subgroupInclusiveAdd(v);
      if (y < pc.size.y) imageStore(table, ivec2(x, y), v);
      carry = subgroupShuffle(v, last);
    }
  }
}
