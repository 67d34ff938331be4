// Moment soft shadow mapping (JCGT §4): blocker search with one query of the integer summed-area
// table over a grid-aligned region, average blocker depth (Eq. 4), penumbra of the directional
// area light, umbra early-out, nine-region filter (16 lookups), depth bias growing with the
// filter; the per-pixel math is include/msm/soft.h (its recipe at the end), shared with the CPU.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/soft.h"
layout(binding = 2) uniform usampler2D sat_table;
layout(binding = 3) uniform sampler2D unused_second_image; // the shading layout of every filtered technique
#include "shading.glsl"

uvec4 table(int x, int y) { return x < 0 || y < 0 ? uvec4(0u) : texelFetch(sat_table, ivec2(x, y), 0); }

float shadow_intensity(ShadowLookup s) {
  int size = int(frame.shadow_map.x);
  ivec2 map = ivec2(size);
  int width = frame.soft_kernel.x;
  uint scale = uint(frame.soft_kernel.y);
  vec2 spread = vec2(frame.soft.x, frame.soft.y);
  float zf = msm_signed_depth(s.z);
  vec2 position = s.t + 0.5f; // texel i covers [i, i + 1) in sat.h / soft.h
  vec2 hs = msm_soft_search_half_width(spread, zf, -1.0f, width);
  SatRect r = msm_soft_search_rect(position, hs, map);
  uvec4 sum = msm_sat_rect_sum(table(r.hi.x, r.hi.y), table(r.lo.x - 1, r.hi.y), table(r.hi.x, r.lo.y - 1),
                               table(r.lo.x - 1, r.lo.y - 1));
  BlockerResult blocker = msm_soft_blocker4(msm_sat_rect_average(sum, msm_sat_rect_texels(r), scale), zf);
  if (msm_soft_in_umbra(blocker, frame.soft.w)) return 1.0f;
  vec2 hp = msm_soft_penumbra_half_width(spread, zf, blocker.depth, width);
  SoftRegion region = msm_soft_region(position, hp, map);
  SatFilter f = msm_sat_filter(region.lo, region.hi);
  SatSamples16 t;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) t.s[4 * j + i] = table(f.x[i], f.y[j]);
  // The receiver plane's slope in [-1,1] depth per texel.
  float zb = zf - msm_soft_depth_bias(hp, 2.0f * s.depth_per_texel, frame.soft.z);
  return msm_soft_shadow4(msm_sat_filter_average(t, f, scale), zb, frame.soft.w);
}
