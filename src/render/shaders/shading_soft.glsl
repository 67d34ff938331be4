// Soft shadows from integer summed-area tables (JCGT §4): the per-pixel flow is soft.h's, composed
// there once (msm_soft_moment_flow, msm_soft_cssm_flow) and shared with the CPU and the device
// tests; this shader supplies the table fetch and the frame's values. Three moment techniques, one
// specialization each: mssm4 (Θ4*, one table), mssm6 (Θ6*, two tables, Kneiphof §4.2) and vssm (two
// moments, naive variance soft shadows: the baseline), and the convolution soft shadows cssm8 /
// cssm16 (cssm.h: CSM tiles stacked in one table).
#include "msm/render/bindings.h"
layout(binding = MSM_BINDING_SHADING_SHADOW_MAP) uniform usampler2DArray sat_table;
layout(binding = MSM_BINDING_SHADING_SHADOW_MAP1) uniform usampler2DArray
    sat_table1; // six moments: b4, b6; else the first again
#include "shading.glsl"
#include "soft_clamps.glsl"
#include "soft_light.glsl"

// soft.h's fetch: S(x, y) of the light's table `table`. Six moments: table 1 is the second table.
// CSSM: tile `table` lies `table` shadow-map heights further along y; its row -1 is the previous
// tile's last row.
uvec4 sat_fetch(int x, int y, int table) {
  bool cssm = msm_technique_is_cssm(kTechnique);
  int row = cssm ? y + table * int(frame.shadow_map.x) : y;
  if (x < 0 || row < 0) return uvec4(0u);
  ivec3 at = ivec3(x, row, shadow_layer);
  return !cssm && table == 1 ? texelFetch(sat_table1, at, 0) : texelFetch(sat_table, at, 0);
}
#define MSM_SOFT_FETCH sat_fetch
#include "msm/soft.h"

float shadow_intensity(ShadowLookup s) {
  SoftLight light = soft_light(shadow_layer, s);
  SoftSetup k = SoftSetup(ivec2(int(frame.shadow_map.x)), frame.soft_kernel.x, uint(frame.soft_kernel.y), light.spread,
                          light.near_depth, light.perspective, soft_constant_bias(shadow_layer, s), frame.soft.w,
                          frame.technique_params);
  // The receiver plane's slope: ShadowLookup's is in [0,1] depth per texel, soft.h's in [-1,1].
  SoftFragment f = SoftFragment(s.t + 0.5f, s.z, 2.0f * s.depth_per_texel);
  if (msm_technique_is_cssm(kTechnique)) {
    SoftShadow r =
        msm_soft_cssm_flow(k, f, msm_cssm_params(msm_technique_cssm_frequencies(kTechnique), frame.technique_params));
    count_soft_lookup(r.penumbra_clamped);
    return r.shadow;
  }
  int moments = kTechnique == MSM_TECH_MSSM6 ? 6 : (kTechnique == MSM_TECH_VSSM ? 2 : 4);
  SoftShadow r = msm_soft_moment_flow(k, f, moments);
  count_soft_lookup(r.penumbra_clamped);
  return r.shadow;
}
