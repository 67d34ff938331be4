// Transmittance-weighted prefix sums along the rows of the rectified map (JCGT §5.1.1, the scheme of
// Appendix C): groups of 8 x 8 threads, eight rows per group and eight threads per row; walking the
// row in blocks of eight texels, every thread sums the whole row (eight times the reads, which the
// texture cache absorbs) and writes the one normalized prefix sum of its column in the block, so
// that the writes of a block are coalesced. Weights w(j, v) and Δ(v) are rectification.h's.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/rectification_uniforms.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, binding = 0) uniform RectificationBlock { RectificationUniforms rect; };
layout(binding = 1) uniform sampler2D rectified; // float moments, texelFetch only
layout(binding = 2, rgba16) uniform writeonly image2D prefix_sums;

void main() {
  ivec2 size = ivec2(int(rect.map.x), int(rect.map.y));
  int row = int(gl_WorkGroupID.x) * 8 + int(gl_LocalInvocationID.y);
  int column = int(gl_LocalInvocationID.x);
  if (row >= size.y) return;
  RectifiedBounds b = msm_rectified_bounds_of(rect);
  float delta = msm_rectified_row_step(b, (float(row) + 0.5f) / float(size.y), float(size.x));
  float extinction = rect.map.w;
  vec4 sum = vec4(0.0f);
  float weight_sum = 0.0f;
  for (int x0 = 0; x0 < size.x; x0 += 8) {
    vec4 mine = vec4(0.0f);
    for (int k = 0; k < 8 && x0 + k < size.x; ++k) {
      float w = msm_prefix_sum_weight(extinction, delta, float(x0 + k));
      sum += w * texelFetch(rectified, ivec2(x0 + k, row), 0);
      weight_sum += w;
      if (k == column) mine = sum / weight_sum;
    }
    if (x0 + column < size.x) imageStore(prefix_sums, ivec2(x0 + column, row), mine);
  }
}
