// Moment soft shadows (mssm4) in the three.js package, from the shared headers: what a depth texel
// of a directional light's map becomes in its 32-bit integer summed-area table (sat.h), the
// receiver plane's slope from the screen derivatives of three.js's shadow coordinates, and the
// lookup, which is soft.h's per-pixel flow (msm_soft_moment_flow, the renderer's
// shading_soft.glsl) over the package's table fetch with the renderer's settings for mssm4.
// A SHARED header: shared.h's rules apply. GLSL: the including shader defines
//     uvec4 msm_three_sat_fetch(int x, int y, int table)   (S(x, y) of the table, 0 at x or y = -1)
// after this header; C++ passes a callable fetch first, as to soft.h's flow.
#ifndef MSM_THREE_SOFT_H
#define MSM_THREE_SOFT_H
#include "msm/config.h"
#include "msm/render/frame.h"
#include "msm/sat.h"
#include "msm/shared.h"
#include "msm_three.h"
#if !MSM_CPP
uvec4 msm_three_sat_fetch(int x, int y, int table);
#define MSM_SOFT_FETCH msm_three_sat_fetch
#endif
#include "msm/soft.h"

MSM_BEGIN

// The renderer's kernel width W for mssm4 (the technique's default soft kernel): the table keeps
// log2((2^32 - 1) / W²) bits per moment; soft.h's queries stay within W × W texels.
const int MSM_THREE_SOFT_KERNEL = 27;

// A depth texel's entry of the table before the prefix sums: Θ4* of its moments (msm_three_generate,
// the renderer's mssm4 generation) quantized for kernels of W × W texels.
MSM_FN uvec4 msm_three_sat_texel(float unit_depth, int kernel_width) {
  return msm_sat_quantize(msm_three_generate(MSM_THREE_MSSM4, unit_depth), msm_sat_scale(kernel_width * kernel_width));
}

// The receiver plane's [0,1] depth per texel along the map's axes, from the screen-space
// derivatives (dFdx, dFdy) of (texel x, texel y, [0,1] depth): the plane through the fragment
// that the derivatives span, dz = g · dt, solved for g (Cramer's rule). The renderer takes it
// from the normal; three.js's getShadow has the coordinates only. Degenerate (a receiver seen edge
// on, or a helper pixel): 0. Clamped as the renderer clamps it (frame.h).
MSM_FN vec2 msm_three_depth_per_texel(vec3 d_dx, vec3 d_dy) {
  float det = d_dx.x * d_dy.y - d_dx.y * d_dy.x;
  if (!(abs(det) > 1e-12f)) return vec2(0.0f);
  vec2 g = vec2(d_dx.z * d_dy.y - d_dx.y * d_dy.z, d_dx.x * d_dy.z - d_dx.z * d_dy.x) / det;
  if (!(abs(g.x) < 1e30f && abs(g.y) < 1e30f)) return vec2(0.0f);
  return clamp(g, vec2(-MSM_MAX_RECEIVER_DEPTH_SLOPE), vec2(MSM_MAX_RECEIVER_DEPTH_SLOPE));
}

// mssm4's technique parameters (techniques.h's defaults: JCGT Eq. (4) with ε = MSM_BLOCKER_EPSILON).
MSM_FN vec4 msm_three_soft_params() { return vec4(MSM_BLOCKER_EPSILON, MSM_BLOCKER_EPSILON, 0.0f, 0.0f); }

// The flow's constant bias in [-1,1] depth: the renderer's mssm4 depth bias (in [0,1] depth) doubled.
MSM_FN float msm_three_soft_constant_bias() { return 2.0f * MSM_DEPTH_BIAS_AREA_LIGHT; }

MSM_END

#endif // MSM_THREE_SOFT_H

// The lookup, over the fetch (outside the include guard, as soft.h's flow).
#if defined(MSM_SOFT_FLOW) && !defined(MSM_THREE_SOFT_FLOW)
#define MSM_THREE_SOFT_FLOW
MSM_BEGIN
// A directional light's soft shadow at three.js's shadow coordinate `coord` (xy in [0,1] over the
// size.x × size.y map, z the [0,1] depth with three.js's bias); light = (tan of the light's half
// angular diameter, world units per unit of [-1,1] depth, world units per texel along x and y);
// depth_per_texel from msm_three_depth_per_texel. The table holds msm_three_sat_texel's values for
// kernel_width, summed.
MSM_SOFT_FLOW_FN SoftShadow msm_three_soft_shadow(MSM_SOFT_FETCH_PARAM ivec2 size, vec4 light, int kernel_width,
                                                  vec3 coord, vec2 depth_per_texel) {
  SoftSetup k = SoftSetup(size, kernel_width, msm_sat_scale(kernel_width * kernel_width),
                          msm_soft_spread(vec2(light.x), light.y, vec2(light.z, light.w)), -1.0f, false,
                          msm_three_soft_constant_bias(), MSM_SOFT_UMBRA_EPSILON, msm_three_soft_params());
  SoftFragment f = SoftFragment(vec2(coord.x, coord.y) * vec2(size), coord.z, 2.0f * depth_per_texel);
  return msm_soft_moment_flow(MSM_SOFT_FETCH_ARG k, f, 4);
}
MSM_END
#endif
