// The running sums along the lines of the table (rows or columns), the step both passes of the
// simple scheme (sat_rows.glsl, sat_columns.glsl) and of the subgroup scheme (sat_subgroup_rows.glsl,
// sat_subgroup_columns.glsl) take, in place or from the moments. The including file declares the
// image `table`, defines uvec4 sat_scan_load(ivec2 p) (the value the sum adds at texel p),
// SAT_ALONG_ROWS where the lines are rows (else columns), and SAT_SUBGROUP for the subgroup scheme.
#ifdef SAT_ALONG_ROWS
#define SAT_LINES pc.size.y
#define SAT_LENGTH pc.size.x
#define SAT_TEXEL(line, i) ivec2(i, line)
#else
#define SAT_LINES pc.size.x
#define SAT_LENGTH pc.size.y
#define SAT_TEXEL(line, i) ivec2(line, i)
#endif

#ifndef SAT_SUBGROUP
// One thread per line.
void main() {
  int line = int(gl_GlobalInvocationID.x);
  if (line >= SAT_LINES) return;
  uvec4 sum = uvec4(0u);
  for (int i = 0; i < SAT_LENGTH; ++i) {
    sum += sat_scan_load(SAT_TEXEL(line, i));
    imageStore(table, SAT_TEXEL(line, i), sum);
  }
}
#else
// One subgroup per line, in chunks of as many texels as the subgroup has active lanes: the chunk's
// inclusive prefix sums (subgroupInclusiveAdd) plus the carry of the chunks before it, which then
// grows by the chunk's total, the last lane's sum (subgroupShuffle). Lines are spread over the
// subgroups of the whole dispatch (a grid-stride loop).
void main() {
  const int lanes = int(subgroupAdd(1u));                 // active lanes: the chunk width
  const int rank = int(subgroupExclusiveAdd(1u));         // this lane's texel in the chunk
  const uint last = subgroupMax(gl_SubgroupInvocationID); // the lane holding the chunk's total
  const int subgroups = int(gl_NumWorkGroups.x * gl_NumSubgroups);
  for (int line = int(gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID); line < SAT_LINES; line += subgroups) {
    uvec4 carry = uvec4(0u); // wraps modulo 2^32, as the CPU's sums
    for (int i0 = 0; i0 < SAT_LENGTH; i0 += lanes) {
      int i = i0 + rank;
      uvec4 v = i < SAT_LENGTH ? sat_scan_load(SAT_TEXEL(line, i)) : uvec4(0u);
      v = carry + subgroupInclusiveAdd(v);
      if (i < SAT_LENGTH) imageStore(table, SAT_TEXEL(line, i), v);
      carry = subgroupShuffle(v, last);
    }
  }
}
#endif
