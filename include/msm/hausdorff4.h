// Hausdorff four-moment shadow mapping: the sharp lower bound of Z(z < zf) over distributions on
// a bounded depth interval [lo, hi] (2015 §4: [0,1]; works for [-1,1] too). Knowing the depth
// range darkens short-range shadows slightly compared with Hamburger 4MSM.
// Derivation (checked against the LP oracle in tests): if the Hamburger canonical representation
// through zf has both roots in [lo, hi], it is feasible on [lo, hi] and therefore optimal there.
// Otherwise the optimum puts mass on both interval ends: atoms {lo, zf, zfree, hi}, where zfree
// is the unique point such that the fourth moment matches, E[(z-lo)(z-hi)(z-zf)(z-zfree)] = 0.
// Precondition: b biased (bias.h) for the same depth convention as lo, hi and zf.
// Cost: the Hamburger solve plus, in the four-atom branch, ~40 flops and three divisions.
#ifndef MSM_HAUSDORFF4_H
#define MSM_HAUSDORFF4_H
#include "msm/hamburger4.h"
#include "msm/shared.h"

MSM_BEGIN

MSM_FN float msm_hausdorff4_lower(vec4 b, float zf, float lo, float hi) {
  if (zf <= lo) return 0.0f;
  if (zf > hi) return 1.0f;
  Hamburger4Roots r = msm_hamburger4_roots(b, zf);
  if (r.z2 >= lo && r.z3 <= hi) return msm_hamburger4_lower_from_roots(b, zf, r);
  // zfree = E[z r(z)] / E[r(z)] with r(z) = (z-lo)(z-hi)(z-zf) = z³ - s1 z² + s2 z - s3.
  float s1 = lo + hi + zf, s2 = lo * hi + lo * zf + hi * zf, s3 = lo * hi * zf;
  float er = msm_expect_cubic(b, lo, hi, zf);
  float ezr = b[3] - s1 * b[2] + s2 * b[1] - s3 * b[0];
  float zfree = ezr / er;
  float shadow = msm_four_atom_weight(b, lo, zf, zfree, hi);
  if (zfree < zf) shadow += msm_four_atom_weight(b, zfree, lo, zf, hi);
  // The Hausdorff bound is never below the Hamburger one (a smaller feasible set). Rounded
  // moments on the boundary of the moment space of [lo, hi] (e.g. a single depth biased towards
  // δ(lo)/2 + δ(hi)/2, JCGT §2.5) are representable by no distribution on [lo, hi]; the
  // four-atom formula then returns nonsense and the Hamburger bound is the safe answer.
  return msm_saturate(max(shadow, msm_hamburger4_lower_from_roots(b, zf, r)));
}

MSM_END

#endif // MSM_HAUSDORFF4_H
