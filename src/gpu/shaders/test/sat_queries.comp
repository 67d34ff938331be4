// The shared table queries and soft.h's per-pixel flow on the device (sat_queries.h), one query per
// invocation, for sat_builder_test.cpp to compare with the same code on the CPU.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/shared.h"

layout(local_size_x = 64) in;

uvec4 sat_fetch(int x, int y, int table); // below the bindings and push constants, which it reads
#define MSM_SOFT_FETCH sat_fetch
#include "sat_queries.h"

// Moment techniques: the first and the second table (six moments); CSSM: the stacked tiles in the first.
layout(binding = MSM_BINDING_SAT_QUERIES_TABLE0, rgba32ui) uniform readonly uimage2D table0;
layout(binding = MSM_BINDING_SAT_QUERIES_TABLE1, rgba32ui) uniform readonly uimage2D table1;
layout(binding = MSM_BINDING_SAT_QUERIES_QUERIES, std430) readonly buffer Queries { SatQuery queries[]; };
layout(binding = MSM_BINDING_SAT_QUERIES_RESULTS, std430) writeonly buffer Results { SatQueryResult results[]; };
layout(push_constant) uniform PushBlock { SatQueryPush pc; };

uvec4 sat_fetch(int x, int y, int table) {
  bool cssm = pc.moments == 0;
  int row = cssm ? y + table * pc.size.y : y;
  if (x < 0 || row < 0) return uvec4(0u);
  return !cssm && table == 1 ? imageLoad(table1, ivec2(x, row)) : imageLoad(table0, ivec2(x, row));
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  results[i] = msm_test_sat_query(queries[i], pc);
}
