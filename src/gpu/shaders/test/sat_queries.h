// The device test of the shared table queries and of soft.h's per-pixel flow: the layout of its
// bindings, buffers and push constants, and one query, the same code in sat_queries.comp (the device) and
// sat_builder_test.cpp (the CPU). It composes nothing: it calls the flow the renderer's shading
// calls (msm_soft_moment_flow, msm_soft_cssm_flow). Shared-header rules (include/msm/shared.h);
// include it after soft.h's flow (GLSL: after defining MSM_SOFT_FETCH).
#ifndef MSM_GPU_TEST_SAT_QUERIES_H
#define MSM_GPU_TEST_SAT_QUERIES_H
#include "msm/soft.h"

#define MSM_BINDING_SAT_QUERIES_TABLE0 0 // storage images: the tables
#define MSM_BINDING_SAT_QUERIES_TABLE1 1
#define MSM_BINDING_SAT_QUERIES_QUERIES 2 // storage buffers: SatQuery[] in, SatQueryResult[] out
#define MSM_BINDING_SAT_QUERIES_RESULTS 3

MSM_BEGIN

struct SatQuery {
  vec4 region;   // (lo.x, lo.y, hi.x, hi.y) in texels: the region of the raw queries
  vec4 fragment; // (x, y) in texels, depth in [0,1], the receiver's slope along x in [-1,1] depth
                 // per texel (0 along y)
};
struct SatQueryResult {
  uvec4 rect_sum; // msm_soft_rect_sum over the grid rectangle of `region` (table 0)
  vec4 filtered;  // msm_soft_filter_average over `region` (table 0)
  vec4 soft;      // the flow: (shadow, blocker depth, search-region shadow, penumbra half-width x)
};
// The push constants (std430 in GLSL): the flow's setup, and which flow.
struct SatQueryPush {
  ivec2 size;       // the shadow map (one tile)
  uint scale;       // msm_sat_scale(kernel_width²)
  int kernel_width; // W
  vec2 spread;      // texels per unit of [-1,1] depth
  uint count;       // queries
  int moments;      // 4, 6 or 2: msm_soft_moment_flow; 0: msm_soft_cssm_flow
  vec4 params;      // the technique's parameters
  ivec4 cssm;       // x: CSM frequencies of the CSSM technique, yzw: unused
};

// The constant bias of the flow in this test, [-1,1] depth.
const float MSM_TEST_SOFT_CONSTANT_BIAS = 1.0e-4f;

// One query: the raw table queries over `region` and the flow at `fragment`.
MSM_SOFT_FLOW_FN SatQueryResult msm_test_sat_query(MSM_SOFT_FETCH_PARAM SatQuery q, SatQueryPush pc) {
  vec2 lo = vec2(q.region[0], q.region[1]), hi = vec2(q.region[2], q.region[3]);
  uvec4 rect_sum = msm_soft_rect_sum(MSM_SOFT_FETCH_ARG msm_sat_grid_rect(lo, hi, pc.size), 0);
  vec4 filtered = msm_soft_filter_average(MSM_SOFT_FETCH_ARG msm_sat_filter(lo, hi), pc.scale, 0);
  SoftSetup k = SoftSetup(pc.size, pc.kernel_width, pc.scale, pc.spread, -1.0f, false, MSM_TEST_SOFT_CONSTANT_BIAS,
                          MSM_SOFT_UMBRA_EPSILON, pc.params);
  SoftFragment f = SoftFragment(vec2(q.fragment[0], q.fragment[1]), q.fragment[2], vec2(q.fragment[3], 0.0f));
  SoftShadow s;
  if (pc.moments == 0)
    s = msm_soft_cssm_flow(MSM_SOFT_FETCH_ARG k, f, msm_cssm_params(pc.cssm.x, pc.params));
  else
    s = msm_soft_moment_flow(MSM_SOFT_FETCH_ARG k, f, pc.moments);
  return SatQueryResult(rect_sum, filtered, vec4(s.shadow, s.blocker_depth, s.search_shadow, s.penumbra.x));
}

MSM_END

#endif // MSM_GPU_TEST_SAT_QUERIES_H
