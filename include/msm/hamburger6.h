// Hamburger six-moment shadow mapping: the sharp bounds of Z(z < zf) over all distributions on
// the real line with moments (1, b1, ..., b6) (JCGT Algorithm 1 with m = 6, §5.4), and the
// weighted combination of both bounds used for prefiltered single scattering (JCGT §5.3-5.4).
// Precondition for every function: b is biased (bias.h, MSM_REP6_*), so the Hankel matrix
// B = (b_{j+k}), j,k = 0..3, is positive definite; depth convention is the caller's.
#ifndef MSM_HAMBURGER6_H
#define MSM_HAMBURGER6_H
#include "msm/moments.h"
#include "msm/roots.h"
#include "msm/shared.h"

MSM_BEGIN

// The three real roots of q[3] z³ + q[2] z² + q[1] z + q[0] with Blinn's branch that depresses
// around the leading coefficient (Blinn, "How to solve a cubic equation, part 5", 2007), sorted
// ascending. Precondition: three real roots and q[3] != 0.
//   monic form z³ + 3B z² + 3C z + D, Hessian δ1 = C - B², δ2 = D - BC, δ3 = BD - C²,
//   discriminant Δ = 4 δ1 δ3 - δ2² (>= 0 for three real roots),
//   depressed cubic t³ + 3 δ1 t + D̄ with z = t - B and D̄ = δ2 - 2 B δ1,
//   t = 2 sqrt(-δ1) cos(φ + 2πk/3), 3φ = atan2(sqrt(Δ), -D̄) in [0, π].
// Since φ is in [0, π/3], cos(φ + 2π/3) <= cos(φ - 2π/3) <= cos(φ): the roots come out sorted.
// Every root is computed as t - B, so each carries an absolute error of ~eps·max|z|.
MSM_FN vec3 msm_cubic_roots_leading(vec4 q) {
  float inv_q3 = 1.0f / q[3];
  float B = q[2] * inv_q3 / 3.0f;
  float C = q[1] * inv_q3 / 3.0f;
  float D = q[0] * inv_q3;
  float delta1 = C - B * B;
  float delta2 = D - B * C;
  float delta3 = B * D - C * C;
  float discriminant = 4.0f * delta1 * delta3 - delta2 * delta2;
  float depressed_d = delta2 - 2.0f * B * delta1;
  // Rounding may push Δ or -δ1 slightly below zero for nearly coincident roots.
  float phi = atan(sqrt(max(discriminant, 0.0f)), -depressed_d) / 3.0f;
  float c = cos(phi);
  float s = sin(phi);
  float scale = 2.0f * sqrt(max(-delta1, 0.0f));
  const float HALF_SQRT3 = 0.86602540378443865f;
  return vec3(scale * (-0.5f * c - HALF_SQRT3 * s) - B, // cos(φ + 2π/3)
              scale * (-0.5f * c + HALF_SQRT3 * s) - B, // cos(φ - 2π/3)
              scale * c - B);                           // cos(φ)
}

// (min, median, max) of three values.
MSM_FN vec3 msm_sort3(float a, float b, float c) {
  float lo = min(a, b);
  float hi = max(a, b);
  return vec3(min(lo, c), max(lo, min(hi, c)), max(hi, c));
}

// The three real roots of q[3] z³ + q[2] z² + q[1] z + q[0], sorted ascending. Precondition: all
// three roots are real (true for q of msm_hamburger6_roots with valid input), q != 0.
//
// JCGT §5.4.1 computes all three roots with one of Blinn's two branches instead of Blinn's
// combination (largest root from one branch, smallest from the other). Here one branch computes
// all three roots too, but which one is picked per call:
//  - the leading-coefficient branch above, as in the paper, or
//  - the same branch on the reversed polynomial q[0] w³ + q[1] w² + q[2] w + q[3], whose roots
//    are w = 1/z (what Blinn's other branch computes).
// Why: the leading-coefficient branch divides by q[3], and |q[3]| << max|q| does occur for valid
// moments: the blocker search's configuration, an occluder plus the receiver at zf, sends one
// root towards infinity. There |q[3]| / max|q| reaches 4e-6 (and q[3] came out exactly 0, giving
// NaN, in ~1 of 20000 cases before the LDLᵀ below used fused multiply-adds); the paper's branch
// alone then loses ~eps·max|z| on the moderate roots, which moved the lower bound by up to
// 7.5e-3 in 1e6 such configurations.
// Each branch loses ~eps times the largest magnitude among its roots (absolute error eps·max|z|
// on z, or eps·max|1/z| on w = 1/z, i.e. eps·max|1/z|·z² on z). The branch with the smaller
// bound on that magnitude is taken, from the coefficients without division:
// max|z| <= (|q2| + 2 sqrt(q2² - 3 q1 q3)) / (3 |q3|) (= |B| + 2 sqrt(-δ1) above) and
// max|1/z| <= (|q1| + 2 sqrt(q1² - 3 q2 q0)) / (3 |q0|). For roots of magnitude O(1) this is the
// paper's branch; q[3] = 0 always takes the reversed one, q[0] = 0 the leading one.
// In the reversed branch the root of largest magnitude (smallest |w|) would only be accurate to
// ~eps·max|1/z|·|z| relative; it is recomputed from the sum of the roots, -q[2]/q[3], instead.
// A root at infinity (q[3] = 0) comes back finite: 1/w for the w = 0 that rounding leaves at
// ~eps·max|w|, or MSM_ROOT_LIMIT (roots.h) where it stays below 1/MSM_ROOT_LIMIT; every root is
// clamped to ±MSM_ROOT_LIMIT. Its weight is then ~0, and nothing downstream divides 0 by 0 or
// overflows (the weights never raise a node to a power higher than 3: 1e24 at most).
MSM_FN vec3 msm_cubic_roots(vec4 q) {
  float spread_z = abs(q[2]) + 2.0f * sqrt(max(q[2] * q[2] - 3.0f * q[1] * q[3], 0.0f));
  float spread_w = abs(q[1]) + 2.0f * sqrt(max(q[1] * q[1] - 3.0f * q[2] * q[0], 0.0f));
  if (spread_z * abs(q[0]) <= spread_w * abs(q[3])) {
    vec3 z = msm_cubic_roots_leading(q);
    return vec3(msm_clamp_root(z[0]), msm_clamp_root(z[1]), msm_clamp_root(z[2]));
  }
  vec3 w = msm_cubic_roots_leading(vec4(q[3], q[2], q[1], q[0]));
  vec3 z;
  for (int i = 0; i < 3; ++i)
    z[i] = (abs(w[i]) * MSM_ROOT_LIMIT > 1.0f) ? 1.0f / w[i] : ((w[i] < 0.0f) ? -MSM_ROOT_LIMIT : MSM_ROOT_LIMIT);
  z = msm_sort3(z[0], z[1], z[2]);
  // The far root is z[0] or z[2] (the middle one never has the largest magnitude).
  bool far_low = abs(z[0]) > abs(z[2]);
  float others = z[1] + (far_low ? z[2] : z[0]);
  float far_root = (q[3] != 0.0f) ? msm_clamp_root(-q[2] / q[3] - others) : (far_low ? z[0] : z[2]);
  return far_low ? msm_sort3(far_root, z[1], z[2]) : msm_sort3(z[0], z[1], far_root);
}

// Floors of the pivots D1, D2, D3 of the LDLᵀ below (for invalid input only, see there).
const float MSM_MIN_PIVOT6_1 = 1.0e-10f;
const float MSM_MIN_PIVOT6_2 = 1.0e-12f;
const float MSM_MIN_PIVOT6_3 = 1.0e-14f;

// The canonical representation through zf: B q = (1, zf, zf², zf³) solved by LDLᵀ (Cholesky
// without square roots, JCGT §5.4.1); z[0] <= z[1] <= z[2] are the roots of Σ q[j] z^j.
struct Hamburger6Roots {
  vec4 q;
  vec3 z;
};

// A vector that some biased texel can have: finite, with variance above MSM_MIN_PIVOT6_1 (biased
// six-moment vectors have D1 >= 2.8e-6, see below; a NaN texel stored as UNORM code 0 decodes to
// D1 = -1.02).
MSM_FN bool msm_hamburger6_valid(Moments6 b) {
  return msm_is_finite4(vec4(b.odd, b.even[0])) && msm_is_finite(b.even[1]) && msm_is_finite(b.even[2]) &&
         msm_fma(-b.odd[0], b.odd[0], b.even[0]) > MSM_MIN_PIVOT6_1;
}

// Invalid input (msm_hamburger6_valid false) or a receiver out of range (msm_receiver_in_range,
// roots.h) comes back as q = 0 and all roots at +MSM_ROOT_LIMIT: the bounds then read 0 (lit),
// or 1 behind everything, and w0 = 0, as in hamburger4.h.
MSM_FN Hamburger6Roots msm_hamburger6_roots(Moments6 b, float zf) {
  if (!(msm_hamburger6_valid(b) && msm_receiver_in_range(zf))) return Hamburger6Roots(vec4(0.0f), vec3(MSM_ROOT_LIMIT));
  float b1 = b.odd[0], b3 = b.odd[1], b5 = b.odd[2];
  float b2 = b.even[0], b4 = b.even[1], b6 = b.even[2];
  // B = L D Lᵀ, L unit lower triangular with first column (1, b1, b2, b3),
  // D = diag(1, D1, D2, D3). LiJDj stands for L[i][j] D[j].
  // The differences cancel to ~α for the nearly singular B of simple kernels: each is formed
  // with fused multiply-adds (msm_fma, one rounding per product), as in hamburger4.h. Against
  // the float LDLᵀ written out plainly this cuts the error against JCGT Alg. 1 (m = 6) from p99
  // 2e-5 / max 5e-2 to p99 6e-6 / max 4e-3 (hamburger6_test). The pivots are floored (below)
  // for unbiased or otherwise invalid input only: biased float moments keep D1 >= 2.8e-6,
  // D2 >= 7.9e-7, D3 >= 3.0e-8 (measured over flat receivers and 1-3 Diracs in [-1,1]), and no
  // biased vector of a six-moment storage path was found outside the moment space (edges_test),
  // so the rounding floor of hamburger4.h's D2 is not needed here. msm_at_least, not max(): no
  // NaN reaches a max().
  float D1 = msm_at_least(msm_fma(-b1, b1, b2), MSM_MIN_PIVOT6_1);
  float L21D1 = msm_fma(-b1, b2, b3);
  float L31D1 = msm_fma(-b1, b3, b4);
  float L21 = L21D1 / D1;
  float L31 = L31D1 / D1;
  float D2 = msm_at_least(msm_fma(-L21, L21D1, msm_fma(-b2, b2, b4)), MSM_MIN_PIVOT6_2);
  float L32D2 = msm_fma(-L21, L31D1, msm_fma(-b2, b3, b5));
  float L32 = L32D2 / D2;
  float D3 = msm_at_least(msm_fma(-L32, L32D2, msm_fma(-L31, L31D1, msm_fma(-b3, b3, b6))), MSM_MIN_PIVOT6_3);
  // Forward substitution L y = (1, zf, zf², zf³) (y0 = 1), scaling by D⁻¹, back substitution.
  float y1 = zf - b1;
  float y2 = msm_fma(-L21, y1, msm_fma(zf, zf, -b2));
  float y3 = msm_fma(-L32, y2, msm_fma(-L31, y1, msm_fma(zf * zf, zf, -b3)));
  y1 /= D1;
  y2 /= D2;
  y3 /= D3;
  vec4 q;
  q[3] = y3;
  q[2] = y2 - L32 * q[3];
  q[1] = y1 - L21 * q[2] - L31 * q[3];
  q[0] = 1.0f - b1 * q[1] - b2 * q[2] - b3 * q[3];
  return Hamburger6Roots(q, msm_cubic_roots(q));
}

// Weight of zf in the canonical representation: w0 = 1 / (pᵀ B⁻¹ p) = 1 / Σ q[j] zf^j with
// p = (1, zf, zf², zf³) (2015 supplementary, Proposition 10; as msm_hamburger4_w0). pᵀ B⁻¹ p >= 1
// for positive definite B; just below 1 (rounding) gives 1, a non-positive or NaN value (garbage
// moments, or invalid input with q = 0) gives 0, so that lower <= lower + β w0 <= upper for any
// input (garbage moments gave w0 < 0 and upper < lower in 19% of random vectors before).
MSM_FN float msm_hamburger6_w0(Hamburger6Roots r, float zf) {
  vec4 q = r.q;
  float s = q[0] + zf * (q[1] + zf * (q[2] + zf * q[3]));
  return s >= 1.0f ? 1.0f / s : (s > 0.0f ? 1.0f : 0.0f);
}

// Σ v[l] w[l] over the canonical distribution Σ w[l] δ(z[l]), z = zf and the three roots in any
// order (JCGT §5.4.2): the interpolation polynomial u with u(z[l]) = v[l] in Newton form by
// divided differences, converted to the monomial basis, dotted with (b0, b1, b2, b3) (=
// Σ w[l] u(z[l]) since the canonical distribution has the moments b0..b3). The nodes are
// pairwise distinct for positive definite B in exact arithmetic (the roots are simple and
// Σ q[j] zf^j = 1/w0 > 0).
//
// Computed nodes do coincide for valid input, though: a single depth z0 (or two nearly equal
// ones) under the bias α gives, for receivers zf on a curve in the (z0, zf) plane, a true pair of
// roots around z0 only ~1e-3 apart (5.7e-4 at z0 = -0.92593, zf = 0.2227, long double). A pair that close
// is ill-conditioned: its split moves by ~sqrt of the relative error of q, which the float LDLᵀ of
// a B with condition number ~1/α leaves at ~1e-6. Rounding then sends the discriminant of the
// cubic below 0, msm_cubic_roots_leading clamps it and returns an exact double root (once per
// ~1e5-1e6 random inputs; the GPU's rounding may keep the pair apart). The divided differences
// then formed 0/0 = NaN and msm_saturate turned the lower bound into 0 instead of ~1.
// v is a function of the node (u interpolates values, not slopes), so equal nodes carry equal
// values, and a pair only matters through its combined weight: msm_divided_difference makes
// every difference of equal values exactly 0, whatever the divisor. For a double node this is
// Hermite interpolation with slope 0 there, which the true pair z0 ± δ sees as u(z0 ± δ) =
// v + O(δ²): the pair's combined weight comes out right (a double root is a merged atom, see
// msm_hamburger6_canonical); close but distinct nodes with equal values get the same 0.
MSM_FN float msm_divided_difference(float dv, float dz) {
  // dz == 0 with dv != 0 needs coincident nodes with different values: impossible for v a
  // function of z; the guard keeps invalid input finite.
  return (dv == 0.0f || dz == 0.0f) ? 0.0f : dv / dz;
}

MSM_FN float msm_hamburger6_weighted_sum(Moments6 b, vec4 z, vec4 v) {
  float f01 = msm_divided_difference(v[1] - v[0], z[1] - z[0]);
  float f12 = msm_divided_difference(v[2] - v[1], z[2] - z[1]);
  float f23 = msm_divided_difference(v[3] - v[2], z[3] - z[2]);
  float f012 = msm_divided_difference(f12 - f01, z[2] - z[0]);
  float f123 = msm_divided_difference(f23 - f12, z[3] - z[1]);
  float f0123 = msm_divided_difference(f123 - f012, z[3] - z[0]);
  // u(z) = v0 + (z - z0) (f01 + (z - z1) (f012 + (z - z2) f0123)), expanded from the inside:
  // a(z) = f012 + (z - z2) f0123 = a0 + a1 z
  float a0 = f012 - z[2] * f0123;
  float a1 = f0123;
  // c(z) = f01 + (z - z1) a(z) = c0 + c1 z + c2 z²
  float c0 = f01 - z[1] * a0;
  float c1 = a0 - z[1] * a1;
  float c2 = a1;
  // u(z) = v0 + (z - z0) c(z)
  float u0 = v[0] - z[0] * c0;
  float u1 = c0 - z[0] * c1;
  float u2 = c1 - z[0] * c2;
  float u3 = c2;
  return u0 + u1 * b.odd[0] + u2 * b.even[0] + u3 * b.odd[1];
}

// Sharp lower bound of Z(z < zf): the weight of the roots below zf (JCGT §5.4.2 with v0 = 0,
// v[l] = 1 for z[l] < zf). Note that the paper's v are visibility weights (1 where z[l] >= zf);
// these are shadow weights, so the two differ by 1 - v.
// The root of largest magnitude (r.z[0] or r.z[2]) goes last: the conversion to the monomial
// basis multiplies by z[0], z[1], z[2] only, so a root far away (up to ±MSM_ROOT_LIMIT, see
// msm_cubic_roots) never scales a coefficient.
MSM_FN float msm_hamburger6_lower_from_roots(Moments6 b, float zf, Hamburger6Roots r) {
  if (!msm_receiver_in_range(zf)) return msm_receiver_out_of_range_shadow(msm_hamburger6_valid(b), zf);
  vec4 z = (abs(r.z[0]) > abs(r.z[2])) ? vec4(zf, r.z[1], r.z[2], r.z[0]) : vec4(zf, r.z[1], r.z[0], r.z[2]);
  vec4 v = vec4(0.0f, (z[1] < zf) ? 1.0f : 0.0f, (z[2] < zf) ? 1.0f : 0.0f, (z[3] < zf) ? 1.0f : 0.0f);
  return msm_saturate(msm_hamburger6_weighted_sum(b, z, v));
}

MSM_FN float msm_hamburger6_lower(Moments6 b, float zf) {
  return msm_hamburger6_lower_from_roots(b, zf, msm_hamburger6_roots(b, zf));
}

// Sharp upper bound of Z(z <= zf): lower bound plus the weight of zf (JCGT §5.3, Fig. 2).
MSM_FN float msm_hamburger6_upper(Moments6 b, float zf) {
  Hamburger6Roots r = msm_hamburger6_roots(b, zf);
  return msm_saturate(msm_hamburger6_lower_from_roots(b, zf, r) + msm_hamburger6_w0(r, zf));
}

// Both bounds at once: (lower, upper).
MSM_FN vec2 msm_hamburger6_bounds(Moments6 b, float zf) {
  Hamburger6Roots r = msm_hamburger6_roots(b, zf);
  float lower = msm_hamburger6_lower_from_roots(b, zf, r);
  return vec2(lower, msm_saturate(lower + msm_hamburger6_w0(r, zf)));
}

// The shadow intensity lower + beta·w0 = mix(lower, upper, beta): beta = 0 gives the lower
// bound, beta = 1 the upper bound, linear in between (before the clamp to [0,1]).
// For single scattering (JCGT §5.3.1, §5.4.2) the paper's β weighs w0 in the VISIBILITY, so the
// shadow intensity for the paper's β is msm_hamburger6_blend(b, zf, 1.0f - β).
MSM_FN float msm_hamburger6_blend(Moments6 b, float zf, float beta) {
  Hamburger6Roots r = msm_hamburger6_roots(b, zf);
  float lower = msm_hamburger6_lower_from_roots(b, zf, r);
  return msm_saturate(lower + beta * msm_hamburger6_w0(r, zf));
}

// The whole canonical distribution Σ w[l] δ(z[l]): z[0] = zf, z[1] <= z[2] <= z[3] the roots.
// w[0] = 1 / (pᵀ B⁻¹ p); w[1..3] by Lagrange interpolation on b0..b3:
// w[l] = (b3 - e1 b2 + e2 b1 - e3) / Π_{k != l} (z[l] - z[k]), e1, e2, e3 the elementary
// symmetric polynomials of the other three nodes (the coefficients of Π_{k != l} (z - z[k])).
struct Canonical6 {
  vec4 z;
  vec4 w;
};

MSM_FN float msm_hamburger6_lagrange_weight(Moments6 b, float zl, float za, float zb, float zc) {
  // msm_hamburger6_canonical merges close pairs before calling this; coincident nodes left
  // (invalid input, e.g. unbiased moments of a single depth give a triple root) get weight 0.
  return msm_four_atom_weight(vec4(b.odd[0], b.even[0], b.odd[1], b.even[1]), zl, za, zb, zc);
}

// Roots closer than this are one atom of the canonical distribution (see below).
const float MSM_MERGE_ROOTS6 = 1.0e-2f;

// Weight and position (w, z) of a pair of roots za <= zb merged into one atom; zc is the third
// root. The weight is Σ_{za, zb} w[l], the position the pair's mean Σ w[l] z[l] / Σ w[l], both as
// weighted sums (v = 1 resp. v = z on the pair, 0 at zf and zc), which stay well-conditioned
// however close the pair is (msm_hamburger6_weighted_sum). The far root goes last as there.
MSM_FN vec2 msm_hamburger6_merged_pair(Moments6 b, float zf, float za, float zb, float zc) {
  bool far_first = abs(za) > abs(zc) || abs(zb) > abs(zc);
  vec4 z = far_first ? vec4(zf, zc, za, zb) : vec4(zf, za, zb, zc);
  vec4 ones = far_first ? vec4(0.0f, 0.0f, 1.0f, 1.0f) : vec4(0.0f, 1.0f, 1.0f, 0.0f);
  vec4 depths = far_first ? vec4(0.0f, 0.0f, za, zb) : vec4(0.0f, za, zb, 0.0f);
  float w = msm_hamburger6_weighted_sum(b, z, ones);
  float s = msm_hamburger6_weighted_sum(b, z, depths);
  float mid = 0.5f * (za + zb);
  // s / w clamped to [za, zb] by selects (NaN goes to mid): clamp() of NaN differs between GLM and
  // devices.
  float m = (w > 0.0f) ? s / w : mid;
  return vec2(w, m >= za ? (m <= zb ? m : zb) : (m < za ? za : mid));
}

// A pair of roots closer than MSM_MERGE_ROOTS6 is returned as one atom: position and combined
// weight from msm_hamburger6_merged_pair in the lower slot, weight 0 at the same position in the
// upper slot. Why: such a pair is ill-conditioned (msm_hamburger6_weighted_sum: its split moves
// by ~sqrt of the ~1e-6 relative error of q, i.e. by ~1e-3), and the Lagrange weights divide by
// the split, so each weight of the pair alone may be off by O(1) or come out 0 for an exact
// double root (the bug: both 0, blocker6 returned zf with shadow 0 behind a single occluder),
// while the pair's combined weight and mean are accurate. Merging changes nothing that the
// bounds and the blocker search use (they sum over the roots below zf) unless zf falls between
// the two roots, which is itself ill-conditioned. If all three roots lie within the tolerance
// (invalid input only) the lower pair is merged.
MSM_FN Canonical6 msm_hamburger6_canonical(Moments6 b, float zf) {
  // Invalid input (see msm_hamburger6_roots): no atom besides zf, every weight 0.
  if (!(msm_hamburger6_valid(b) && msm_receiver_in_range(zf)))
    return Canonical6(vec4(zf, MSM_ROOT_LIMIT, MSM_ROOT_LIMIT, MSM_ROOT_LIMIT), vec4(0.0f));
  Hamburger6Roots r = msm_hamburger6_roots(b, zf);
  float z1 = r.z[0], z2 = r.z[1], z3 = r.z[2];
  float w0 = msm_hamburger6_w0(r, zf);
  // Merge only pairs on one side of zf: a pair around zf is what the bounds need split.
  if (z2 - z1 <= MSM_MERGE_ROOTS6 && (z2 < zf) == (z1 < zf)) {
    vec2 pair = msm_hamburger6_merged_pair(b, zf, z1, z2, z3);
    return Canonical6(vec4(zf, pair[1], pair[1], z3),
                      vec4(w0, pair[0], 0.0f, msm_hamburger6_lagrange_weight(b, z3, zf, z1, z2)));
  }
  if (z3 - z2 <= MSM_MERGE_ROOTS6 && (z3 < zf) == (z2 < zf)) {
    vec2 pair = msm_hamburger6_merged_pair(b, zf, z2, z3, z1);
    return Canonical6(vec4(zf, z1, pair[1], pair[1]),
                      vec4(w0, msm_hamburger6_lagrange_weight(b, z1, zf, z2, z3), pair[0], 0.0f));
  }
  return Canonical6(vec4(zf, z1, z2, z3), vec4(w0, msm_hamburger6_lagrange_weight(b, z1, zf, z2, z3),
                                               msm_hamburger6_lagrange_weight(b, z2, zf, z1, z3),
                                               msm_hamburger6_lagrange_weight(b, z3, zf, z1, z2)));
}

// Adaptive overestimation for prefiltered single scattering (JCGT §5.3.1):
// β = (1 + ωlᵀ ωp) / 2 with ωl the unit direction towards the directional light and ωp the unit
// direction from the scattering point towards the camera (the view ray is p - t ωp, JCGT §5.1.1).
// β = 0 at ωp = -ωl (looking into the light, where the epipole's leaking would show) and β = 1
// at ωp = ωl (the antipode, where underestimation would remove all scattering); it varies
// slowly near both. β is the paper's weight of w0 in the VISIBILITY (v0 = β, §5.4.2), i.e.
// β = 1 overestimates scattering: pass 1 - β to msm_hamburger6_blend, which blends shadow.
// Clamped to [0, 1] against directions that are not exactly unit length.
MSM_FN float msm_adaptive_overestimation_beta(vec3 light_dir, vec3 view_dir) {
  return msm_saturate(0.5f + 0.5f * dot(light_dir, view_dir));
}

MSM_END

#endif // MSM_HAMBURGER6_H
