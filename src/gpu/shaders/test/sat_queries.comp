// The shared table queries and the soft-shadow flow of soft_flow.h on the device, one query per
// invocation, for sat_builder_test.cpp to compare with the same code on the CPU.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/shared.h"

layout(local_size_x = 64) in;
layout(binding = 0, rgba32ui) uniform readonly uimage2D table;
struct Query {
  vec4 region;
  vec4 fragment;
};
struct Result {
  uvec4 rect_sum;
  vec4 filtered;
  vec4 soft;
};
layout(binding = 1, std430) readonly buffer Queries { Query queries[]; };
layout(binding = 2, std430) writeonly buffer Results { Result results[]; };
layout(push_constant) uniform Push {
  ivec2 size;
  uint scale;
  int kernel_width;
  vec2 spread;
  uint count;
  uint pad;
} pc;

uvec4 sat_fetch(int x, int y) { return (x < 0 || y < 0) ? uvec4(0u) : imageLoad(table, ivec2(x, y)); }

#include "soft_flow.h"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  SoftFlow r = msm_test_soft_flow(queries[i].region, queries[i].fragment, pc.size, pc.scale, pc.kernel_width, pc.spread);
  results[i].rect_sum = r.rect_sum;
  results[i].filtered = r.filtered;
  results[i].soft = r.soft;
}
