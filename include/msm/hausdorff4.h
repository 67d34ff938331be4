// Hausdorff four-moment shadow mapping: the sharp lower bound of Z(z < zf) over distributions on
// a bounded depth interval [lo, hi] (2015 §4: [0,1]; works for [-1,1] too). Knowing the depth
// range darkens short-range shadows slightly compared with Hamburger 4MSM.
// Derivation (checked against the LP oracle in tests). The bound is attained by the canonical
// representation through zf on [lo, hi] (Markov-Krein): if the Hamburger one has both roots in
// [lo, hi], it is feasible on [lo, hi] and therefore optimal there. Otherwise the optimum puts
// mass on both interval ends: atoms {lo, zf, x, hi} (lo and hi count half in the index, so this
// is the other canonical representation of index 3).
// Precondition: b biased (bias.h) for the same depth convention as lo, hi and zf.
// Cost: the Hamburger solve plus, in the four-atom branch, ~60 flops and three divisions.
#ifndef MSM_HAUSDORFF4_H
#define MSM_HAUSDORFF4_H
#include "msm/hamburger4.h"
#include "msm/roots.h"
#include "msm/shared.h"

MSM_BEGIN

// How many unit roundoffs (2^-24) of the sum of the magnitudes of the terms of s0, s1, s2 and V
// below count as their noise: one. The sum assumes every term's rounding aligned, a worst case
// of the input's own rounding (measured errors of s2 were a quarter of it). Four cost 0.04 on the
// HPG §3.2 pair ½δ(0.915) + ½δ(1) at the far end (K6 of `msm kernels`: 0.455 against a sharp
// 0.499, 0.487 with one), and no edge class needed more (edges_test).
const float MSM_HAUSDORFF_NOISE = 1.0f;

// The four-atom branch. With g(z) = (z - lo)(hi - z) >= 0 on [lo, hi], the measure ν = g μ of the
// optimal μ = w_lo δ(lo) + w_0 δ(zf) + w_x δ(x) + w_hi δ(hi) has atoms at zf and x only (g vanishes
// at the ends), and its moments come from b0..b4:
//   s0 = E[g], s1 = E[g (z - zf)] = c (x - zf), s2 = E[g (z - zf)²] = c (x - zf)²,
// c the ν-weight of x: x - zf = s2 / s1, c = s1² / s2, and V = s0 s2 - s1² >= 0 (Cauchy-Schwarz;
// s0² times ν's variance, 0 when ν is one atom). Eliminating w_hi and w_0 with b0, b1 gives
// L = Z(z < zf) of μ = w_lo + [x < zf] w_x as
//   L (hi - lo) = (hi - b1) - t - V / ((zf - lo) d),
//   x >= zf (s1 >= 0): d = s1 (zf - lo) + s2, t = s0 s1 / d,
//   x <  zf (s1 <  0): d = s2,                t = -c |s1| / (|s1| (hi - zf) + s2), c = s0 - V / s2.
// (Written as L (hi - lo)(zf - lo) = P + corr with P = E[(hi - z)(zf - z)], the quadratic bound
// that knows the interval, P and corr are each ~s0 and cancel to V / d where ν has no spread:
// divided by zf - lo, their rounding made a receiver 2.7e-5 behind an occluder at the near end
// read 0.420 for 0.432. Here only V, which is 0 there, is divided by zf - lo.) Every divisor is
// a sum of non-negative terms. Why not the former Lagrange weights of {lo, zf, x = E[z r] / E[r]}:
// they divided by x - zf and by E[(z-lo)(z-hi)(z-zf)] = -s1, both 0 when μ lives on {lo, zf, hi}
// (an occluder at the near end biased towards ½δ(lo) + ½δ(hi), alone or beside a receiver): 0/0 =
// NaN, which max() kept on the CPU and msm_saturate turned into "lit"; and for a receiver on a
// cluster of nearly equal depths s1 and s2 are rounding noise: x came out just below zf with c ~
// s0, counting the whole cluster as shadow (0.98 against a sharp bound of 0.27).
// Rounding. s0, s1, s2 and V are differences of terms up to ~|b| each; below MSM_HAUSDORFF_NOISE
// unit roundoffs of the sum of those terms' magnitudes (tol0, tol1, tol2, tolv) their values, and
// the sign of s1 (which side of zf x lies on), are noise. Resolved to the light side, the bound of
// the vector within rounding that allows the least shadow: |s1| within tol1 of 0 takes x >= zf
// with s1 >= 0, s2 at least tol2, and V at least tolv (a larger V spreads ν and lowers L; t stays
// within what c <= s0 allows). Beyond rounding, negative s0, s2 or V mean that no distribution on
// [lo, hi] has these moments (below).
MSM_FN float msm_hausdorff4_four_atoms(vec4 b, float zf, float lo, float hi) {
  float b1 = b[0], b2 = b[1], b3 = b[2], b4 = b[3];
  float noise = MSM_HAUSDORFF_NOISE * MSM_FLOAT_ROUNDING;
  // E[(z - lo)(z - hi)] = b2 - (lo + hi) b1 + lo hi.
  float s0 = lo * (b1 - hi) - b2 + hi * b1;
  float tol0 = noise * (abs(b2) + abs((lo + hi) * b1) + abs(lo * hi));
  // E[(z - lo)(z - hi)(z - zf)] = b3 - e1 b2 + e2 b1 - e3 (elementary symmetric e of lo, hi, zf).
  float e1 = lo + hi + zf, e2 = lo * hi + zf * (lo + hi), e3 = lo * hi * zf;
  float s1 = -(b3 - e1 * b2 + e2 * b1 - e3);
  float tol1 = noise * (abs(b3) + abs(e1 * b2) + abs(e2 * b1) + abs(e3));
  // E[(z - lo)(z - hi)(z - zf)²]: the same with the roots lo, hi, zf, zf.
  float f1 = e1 + zf, f2 = e2 + zf * e1, f3 = e3 + zf * e2, f4 = zf * e3;
  float s2 = -(b4 - f1 * b3 + f2 * b2 - f3 * b1 + f4);
  float tol2 = noise * (abs(b4) + abs(f1 * b3) + abs(f2 * b2) + abs(f3 * b1) + abs(f4));
  float v = s0 * s2 - s1 * s1;
  float tolv = noise * (abs(s0 * s2) + s1 * s1) + abs(s0) * tol2 + abs(s2) * tol0 + 2.0f * abs(s1) * tol1;
  // Outside the moment space of [lo, hi] beyond rounding: s0, s2 or V negative (mass beyond the
  // ends, e.g. 16-bit Θ4* storage rounding b2 - b4 below 0 for depths near 0). No distribution
  // on [lo, hi] has these moments, and the formula would extrapolate (a cluster at 0.0023 read 1
  // against a PCF of 0.49): -1 says so, and the caller keeps the Hamburger bound, which is a lower
  // bound for every distribution on the line.
  if (s0 < -tol0 || s2 < -tol2 || v < -tolv) return -1.0f;
  s0 = msm_at_least(s0, 0.0f);
  s2 = msm_at_least(s2, tol2);
  v = msm_at_least(v, tolv); // the light side (above)
  float t = 0.0f, d = s2;
  if (s1 < -tol1) {
    float c = msm_at_least(s0 - v / s2, 0.0f);
    t = -c * (-s1) / (-s1 * (hi - zf) + s2);
  } else {
    float a = msm_at_least(s1, 0.0f);
    d = a * (zf - lo) + s2;
    t = s0 * a / d;
  }
  return ((hi - b1) - t - v / ((zf - lo) * d)) / (hi - lo);
}

// Receivers outside the interval: zf <= lo reads 0, zf > hi reads 1; invalid moments
// (msm_hamburger4_valid) and NaN read 0 (lit), as in hamburger4.h.
MSM_FN float msm_hausdorff4_lower(vec4 b, float zf, float lo, float hi) {
  if (!(zf > lo && msm_hamburger4_valid(b))) return 0.0f;
  if (zf > hi) return 1.0f;
  Hamburger4Roots r = msm_hamburger4_roots(b, zf);
  float hamburger = msm_hamburger4_lower_from_roots(b, zf, r);
  if (r.z2 >= lo && r.z3 <= hi) return hamburger;
  float four = msm_hausdorff4_four_atoms(b, zf, lo, hi);
  // The Hausdorff bound is never below the Hamburger one (a smaller feasible set). Moments outside
  // the moment space of [lo, hi] (four = -1 above; or just outside, a single depth at an end
  // biased towards ½δ(lo) + ½δ(hi), JCGT §2.5, where P reads slightly low) are representable by
  // no distribution there, and the Hamburger bound, a valid lower bound for any distribution, is
  // the answer. A select, not max(): no NaN reaches here (four is finite for finite b), and the
  // choice is the same on every device.
  return msm_saturate(four > hamburger ? four : hamburger);
}

MSM_END

#endif // MSM_HAUSDORFF4_H
