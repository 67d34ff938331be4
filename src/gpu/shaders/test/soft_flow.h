// The per-pixel flow of moment soft shadows (soft.h's recipe) plus the two raw table queries, one
// source for sat_queries.comp (the device) and sat_builder_test.cpp (the CPU), which each define
// `uvec4 sat_fetch(int x, int y)` (the table value; 0 where x or y is -1) before including it.
// Shared-header rules (include/msm/shared.h).
#ifndef MSM_SOFT_TEST_SOFT_FLOW_H
#define MSM_SOFT_TEST_SOFT_FLOW_H
#include "msm/soft.h"

MSM_BEGIN

struct SoftFlow {
  uvec4 rect_sum; // the grid rectangle of `region` (4 lookups)
  vec4 filtered;  // nine-region box filter of `region` (16 lookups)
  vec4 soft;      // (shadow, average blocker depth, search-region shadow, penumbra half-width x)
};

// region: (lo.x, lo.y, hi.x, hi.y) in texels; fragment: (x, y) in texels, zf ([-1,1]), and the
// receiver's depth gradient per texel along x (y: 0).
MSM_FN SoftFlow msm_test_soft_flow(vec4 region, vec4 fragment, ivec2 size, uint scale, int width, vec2 spread) {
  SatRect r = msm_sat_grid_rect(vec2(region[0], region[1]), vec2(region[2], region[3]), size);
  uvec4 rect_sum = msm_sat_rect_sum(sat_fetch(r.hi.x, r.hi.y), sat_fetch(r.lo.x - 1, r.hi.y),
                                    sat_fetch(r.hi.x, r.lo.y - 1), sat_fetch(r.lo.x - 1, r.lo.y - 1));
  SatFilter f = msm_sat_filter(vec2(region[0], region[1]), vec2(region[2], region[3]));
  SatSamples16 t;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) t.s[4 * j + i] = sat_fetch(f.x[i], f.y[j]);
  vec4 filtered = msm_sat_filter_average(t, f, scale);

  vec2 center = vec2(fragment[0], fragment[1]);
  float zf = fragment[2];
  vec2 hs = msm_soft_search_half_width(spread, zf, -1.0f, width);
  SatRect sr = msm_soft_search_rect(center, hs, size);
  uvec4 sum = msm_sat_rect_sum(sat_fetch(sr.hi.x, sr.hi.y), sat_fetch(sr.lo.x - 1, sr.hi.y),
                               sat_fetch(sr.hi.x, sr.lo.y - 1), sat_fetch(sr.lo.x - 1, sr.lo.y - 1));
  BlockerResult blocker = msm_soft_blocker4(msm_sat_rect_average(sum, msm_sat_rect_texels(sr), scale), zf, scale);
  if (msm_soft_in_umbra(blocker, MSM_SOFT_UMBRA_EPSILON))
    return SoftFlow(rect_sum, filtered, vec4(1.0f, blocker.depth, blocker.shadow, 0.0f));
  vec2 hp = msm_soft_penumbra_half_width(spread, zf, blocker.depth, width);
  SoftRegion pr = msm_soft_region(center, hp, size);
  SatFilter pf = msm_sat_filter(pr.lo, pr.hi);
  SatSamples16 pt;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) pt.s[4 * j + i] = sat_fetch(pf.x[i], pf.y[j]);
  float zb = zf - 1.0e-4f - msm_soft_plane_bias(hp, vec2(fragment[3], 0.0f), 4);
  float shadow = msm_soft_shadow4(msm_sat_filter_average(pt, pf, scale), zb, MSM_SOFT_UMBRA_EPSILON, scale);
  return SoftFlow(rect_sum, filtered, vec4(shadow, blocker.depth, blocker.shadow, hp.x));
}

MSM_END

#endif
