// Average blocker depth for moment soft shadow mapping (JCGT §4.3, Kneiphof et al. 2017 §3.2.1,
// §4.2.2), with four or six moments. The blocker search queries the moments of the search region
// and takes the canonical distribution Σ w[l] δ(z[l]) through the fragment depth (JCGT Alg. 1)
// as the true depth distribution: for up to m/2 surfaces (two with four moments, three with six)
// it is nearly exact (2015 Prop. 4), for m/2 + 1 surfaces one of which lies at zf it is exact
// (2015 Prop. 8), up to the bias in both cases (blocker_test measures how far). Hence:
//  - b are the BIASED moments (bias.h), as everywhere;
//  - zf is the UNBIASED fragment depth (no depth bias added), so that a receiver surface at zf
//    is the known third surface of Prop. 8;
//  - depths are in [-1,1] (JCGT §2.3, as soft.h uses them), and the average blocker depth is
//    clamped to that range, as the authors' Compute4MomentAverageBlockerDepth does: a root of the
//    canonical distribution may lie below -1 (the Hamburger problem knows no depth range, and the
//    bias puts weight ~α there), and it pulled the average down to -2.33 (edges_test), which
//    widened the penumbra beyond any blocker in the map.
#ifndef MSM_BLOCKER_H
#define MSM_BLOCKER_H
#include "msm/config.h"
#include "msm/hamburger4.h"
#include "msm/hamburger6.h"
#include "msm/moments.h"
#include "msm/shared.h"

MSM_BEGIN

// depth: the average blocker depth; shadow: Σ w[l] over the roots z[l] < zf, l >= 1, i.e. the
// sharp lower bound of Z(z < zf) over the search region (the divisor of JCGT Eq. (4) without
// ε). shadow near 1 means the whole search region occludes the fragment: it is in the umbra
// and the filtering step can be skipped (JCGT App. D.4).
struct BlockerResult {
  float depth;
  float shadow;
};

// d clamped to the depth range [-1, 1], and NaN to -1; a receiver in front of the range (zf < -1)
// keeps its own depth (no blocker lies in front of it; -inf is kept at -MSM_ROOT_LIMIT), so the
// result never exceeds zf. Selects, not clamp(): GLSL leaves clamp() of NaN undefined.
MSM_FN float msm_blocker_depth_in_range(float d, float zf) {
  return d > -1.0f ? (d < 1.0f ? d : 1.0f) : (zf < -1.0f ? msm_at_least(zf, -MSM_ROOT_LIMIT) : -1.0f);
}

// JCGT Eq. (4) on a canonical distribution given as up to four nodes with weights; unused
// nodes carry weight 0. z[0] = zf, the other nodes count where z[l] < zf:
// (ε zf + Σ w[l] z[l]) / (ε + Σ w[l]). ε > 0 keeps the quotient defined when nothing occludes
// (it then returns zf: a small filter kernel); larger ε pulls blockers towards the receiver.
MSM_FN BlockerResult msm_blocker_from_canonical(vec4 z, vec4 w, float epsilon) {
  float zf = z[0];
  float weight_sum = 0.0f;
  float depth_sum = 0.0f;
  for (int l = 1; l < 4; ++l) {
    // Weights of a canonical distribution lie in [0, 1]; saturating them only removes
    // float noise for valid input and keeps invalid input (e.g. unbiased moments with
    // coincident roots and infinite weights) finite: the result stays in [min z, zf].
    float occludes = (z[l] < zf) ? msm_saturate(w[l]) : 0.0f;
    weight_sum += occludes;
    depth_sum += occludes * z[l];
  }
  return BlockerResult(msm_blocker_depth_in_range((epsilon * zf + depth_sum) / (epsilon + weight_sum), zf),
                       msm_saturate(weight_sum));
}

// Kneiphof Eq. (19), the upper-bound variant: the average over all nodes z[l] <= zf INCLUDING
// z[0] = zf itself, whose weight w[0] is clamped to [delta1, delta2] (0 < delta1 <= delta2):
// (clamp(w0, δ1, δ2) zf + Σ_{l>=1, z[l] <= zf} w[l] z[l]) / (clamp(w0, δ1, δ2) + Σ ... w[l]).
// Counting w0 (the mass the moments allow at zf, i.e. self shadowing) moves the average towards
// the receiver where the reconstruction is uncertain: harder shadows instead of too soft ones.
// δ1 > 0 keeps the divisor positive. δ1 = δ2 = ε gives Eq. (4) (up to roots exactly at zf).
// shadow is the same lower bound as for Eq. (4), the roots strictly below zf.
MSM_FN BlockerResult msm_blocker_upper_from_canonical(vec4 z, vec4 w, float delta1, float delta2) {
  float zf = z[0];
  float w0 = clamp(msm_saturate(w[0]), delta1, delta2);
  float shadow = 0.0f;
  float weight_sum = w0;
  float depth_sum = w0 * zf;
  for (int l = 1; l < 4; ++l) {
    float wl = msm_saturate(w[l]); // as in msm_blocker_from_canonical
    float below = (z[l] <= zf) ? wl : 0.0f;
    weight_sum += below;
    depth_sum += below * z[l];
    shadow += (z[l] < zf) ? wl : 0.0f;
  }
  return BlockerResult(msm_blocker_depth_in_range(depth_sum / weight_sum, zf), msm_saturate(shadow));
}

// Four moments b = (b1, b2, b3, b4): three nodes (zf, z2, z3) from msm_hamburger4_canonical.
MSM_FN BlockerResult msm_blocker4(vec4 b, float zf, float epsilon) {
  Canonical4 c = msm_hamburger4_canonical(b, zf);
  return msm_blocker_from_canonical(vec4(c.z[0], c.z[1], c.z[2], 0.0f), vec4(c.w[0], c.w[1], c.w[2], 0.0f), epsilon);
}
MSM_FN BlockerResult msm_blocker4(vec4 b, float zf) { return msm_blocker4(b, zf, MSM_BLOCKER_EPSILON); }

MSM_FN BlockerResult msm_blocker4_upper(vec4 b, float zf, float delta1, float delta2) {
  Canonical4 c = msm_hamburger4_canonical(b, zf);
  return msm_blocker_upper_from_canonical(vec4(c.z[0], c.z[1], c.z[2], 0.0f), vec4(c.w[0], c.w[1], c.w[2], 0.0f),
                                          delta1, delta2);
}

// Six moments: four nodes (zf, z1, z2, z3) from msm_hamburger6_canonical (Kneiphof §4.2.1).
MSM_FN BlockerResult msm_blocker6(Moments6 b, float zf, float epsilon) {
  Canonical6 c = msm_hamburger6_canonical(b, zf);
  return msm_blocker_from_canonical(c.z, c.w, epsilon);
}
MSM_FN BlockerResult msm_blocker6(Moments6 b, float zf) { return msm_blocker6(b, zf, MSM_BLOCKER_EPSILON); }

MSM_FN BlockerResult msm_blocker6_upper(Moments6 b, float zf, float delta1, float delta2) {
  Canonical6 c = msm_hamburger6_canonical(b, zf);
  return msm_blocker_upper_from_canonical(c.z, c.w, delta1, delta2);
}

MSM_END

#endif // MSM_BLOCKER_H
