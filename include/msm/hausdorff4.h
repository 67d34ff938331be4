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

// How many unit roundoffs (2^-24) of the terms of s1 and s2 below count as their noise: the input
// moments carry about one rounding each (filtered float moments a few), the evaluation three or
// four more.
const float MSM_HAUSDORFF_NOISE = 4.0f;

// The four-atom branch, written so that every quantity it divides by is a sum of non-negative
// terms. With g(z) = (z - lo)(hi - z) >= 0 on [lo, hi], the measure ν = g μ of the optimal
// μ = w_lo δ(lo) + w_0 δ(zf) + w_x δ(x) + w_hi δ(hi) has atoms at zf and x only (g vanishes at the
// ends), and its moments come from b0..b4:
//   s0 = E[g], s1 = E[g (z - zf)] = c (x - zf), s2 = E[g (z - zf)²] = c (x - zf)²,
// c the ν-weight of x: x - zf = s2 / s1, c = s1² / s2 <= s0 (Cauchy-Schwarz). Eliminating w_hi and
// w_0 with b0, b1 gives L = Z(z < zf) of μ = w_lo + [x < zf] w_x as
//   L (hi - lo)(zf - lo) = P + corr,    P = E[(hi - z)(zf - z)] = b2 - (hi + zf) b1 + hi zf,
//   x >= zf (s1 >= 0): corr = s1² / (s1 (zf - lo) + s2)              (= c (x - zf) / (x - lo)),
//   x <  zf (s1 <  0): corr = c + c (zf - lo) |s1| / (|s1| (hi - zf) + s2)  (= c + c (zf - lo) / (hi - x)).
// P / ((hi - lo)(zf - lo)) alone is E[p] for the quadratic p through (lo, 1), (zf, 0), (hi, 0),
// which lies below the indicator of z < zf on [lo, hi]: a lower bound by itself (the two-moment
// bound that knows the interval); corr >= 0 sharpens it, and corr = 0 where ν has no mass
// besides zf. Why this form: the former Lagrange weights of {lo, zf, x, hi} divided by x - zf and
// by E[(z-lo)(z-hi)(z-zf)] = -s1, both 0 when μ lives on {lo, zf, hi} (an occluder at the near end
// biased towards ½δ(lo) + ½δ(hi), alone or beside a receiver): 0/0 = NaN, which max() kept on the
// CPU and msm_saturate turned into "lit". And for a receiver on a cluster of nearly equal depths,
// s1 and s2 are rounding noise: x came out just below zf with c ~ s0, counting the whole cluster
// as shadow (0.98 against a sharp bound of 0.27).
// Rounding. s1 and s2 are differences of terms up to ~|b| each; below MSM_HAUSDORFF_NOISE unit
// roundoffs of those terms (tol1, tol2) their values, and the sign of s1 (which side of zf x lies
// on), are noise. corr grows with |s1| and shrinks with s2 in both branches, so |s1| is reduced by
// tol1 and s2 raised to at least tol2: the bound of the vector within rounding that allows the
// least shadow, i.e. the light side (a lower bound for every vector the rounding could have come
// from). c is capped at s0 (ν's weight at x is at most all of ν) and P is left as it is (its own rounding moves the result by
// ~2^-24 / (zf - lo), which is the conditioning of the problem: mass at lo and at zf are told apart
// by zf - lo).
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
  // V = s0 s2 - s1² >= 0 (Cauchy-Schwarz for ν): s0² times ν's variance about its mean.
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
  // Light side: the largest V within rounding (a larger V spreads ν and lowers the bound).
  v = msm_at_least(v, tolv);
  // L (hi - lo) = (hi - b1) - t - V / ((zf - lo) d), both branches:
  //   x >= zf: d = s1 (zf - lo) + s2, t = s0 s1 / d;
  //   x <  zf: d = s2, t = -c |s1| / (|s1| (hi - zf) + s2), c = s0 - V / s2 (= s1² / s2 <= s0).
  // This is P + corr above rearranged with P = (zf - lo)(hi - b1) - s0: s0 and corr, each ~s0 and
  // cancelling to V / d where ν has no spread, no longer meet, and only V (which is 0 there) is
  // divided by zf - lo. Written as P + corr, a receiver 2.7e-5 behind an occluder at the near end
  // read 0.420 for 0.432 (float rounding of P and corr, ~5e-7, over 2 (zf - lo) = 5.4e-5).
  float t = 0.0f, d = s2;
  if (s1 < -tol1) {
    float c = s0 - v / s2;
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
