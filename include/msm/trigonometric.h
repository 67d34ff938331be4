// Trigonometric moment shadow mapping (TMSM, 2015 §3.2, §4): the sharp lower bound of Z(z < zf)
// over all distributions Z on [0,1] with given b = E(sin 2πz, cos 2πz, sin 4πz, cos 4πz)
// (Problem 1 of the 2015 paper with the basis of its Eq. (1)), and the sharp upper bound of
// Z(z <= zf). Closed forms plus one bracketed 1-D root search, derived here (the paper's
// supplementary algorithm is not available) and checked against the 2015 LP (Algorithm 1) in
// src/core/trigonometric_test.cpp.
//
// Setting. θ = 2πz maps [0,1] onto the circle, z = 0 and z = 1 onto the same point w = 1, and
// c_k = E(w^k), w = e^{iθ}: c1 = b2 + i b1, c2 = b4 + i b3. A representation may put mass at w = 1
// on z = 1 (not < zf), so G(b, zf) = inf μ(U) over measures μ on the circle with the moments c,
// U = the open arc (0, φ), φ = 2πzf, K = [φ, 2π] the rest. The Toeplitz matrix
// T = (c_{k-j})_{j,k=0..2} is positive semi-definite, definite for distributions with > 2 atoms.
// The upper bound sup Z(z <= zf) = 1 - inf μ(open arc (φ, 2π)) is the same problem for the arc
// from e^{iφ} to 1, so everything below is written for an open arc from e0 to e1 of length L.
//
// Method (each claim checked against the LP on thousands of random cases):
//  1. Canonical representation σ_ξ through a point ξ of the circle (Szegő quadrature): the unique
//     3-atom distribution with the moments c that has an atom at ξ. Its other two atoms are the
//     roots of the kernel polynomial h(w) = Σ h_k w^k, h = T⁻¹ (1, ξ̄, ξ̄²)ᵀ (they lie on the
//     circle); their weights follow by Lagrange interpolation of c_{-1}, c0, c1. Here: σ_end
//     (ξ = e1) and σ_start (ξ = e0), from one LDLᴴ factorization of T.
//  2. If σ_end or σ_start has no atom in the arc, it is a representation with μ(arc) = 0: G = 0.
//     Otherwise both have the same number of atoms in the arc, 1 or 2.
//  3. Every optimum is a distribution with atoms at both arc ends e0, e1 and two more atoms u, v
//     (complementary slackness: the dual trigonometric polynomial p <= 1_arc of degree 2 touches
//     at most there), possibly with a zero weight at an end (then it is σ_end or σ_start). For
//     given u the fourth atom v is a Möbius function of u: the moments force
//     m2 - (u+v) m1 + uv m0 = 0, m_j = E(w^{j-2} (w - e0)(w - e1)). Along this one-parameter
//     family, with the angle x of u between t = the first arc atom of σ_end (there the weight at
//     e0 vanishes) and s = the first arc atom of σ_start (there the weight at e1 vanishes), all
//     weights are >= 0 and f(x) = the weight in the arc is unimodal; its minimum is G. Two types:
//       A (σ_end has one arc atom): v outside the arc, f = w_u; stationary where
//         cot((x-θ0)/2) + cot((x-θ1)/2) + 2 cot((x-y)/2) = 0, i.e. g_A = Im(P̄ (A u² + B u)) = 0;
//       B (two arc atoms): v in the arc, f = w_u + w_v; stationary where
//         |(e0-u)(e0-v)| = |(e1-u)(e1-v)|, i.e. g_B = |e0-u|² |L_0(u)|² - |e1-u|² |L_1(u)|² = 0
//         with L_k(u) = (e_k m0 - m1) u + m2 - e_k m1 = (e_k - v)(u m0 - m1);
//     With v substituted both are trigonometric polynomials of degree 2 in x (the "quartic" of
//     the 2015 paper, §4), with the sign of f'. The bracket [t, s] is scanned in 8 steps for the
//     first sign change of g from - to +, which a safeguarded Newton iteration refines; G is the
//     smallest of the 4-atom weight there and the arc weights of σ_end and σ_start (all three
//     are representations, so each is >= G in exact arithmetic).
//
// Cost (per bound; msm_trig_bounds shares the factorization): the LDLᴴ in double-float (~300
// flops), two kernel polynomials with their quadratics (~350 flops, 4 atan2), the canonical
// weights (~100 flops, 4 sin/cos). That ends ~2/3 of random cases (G = 0 or a canonical
// representation optimal: ~800 flops). The rest adds 9 evaluations of g (~50 flops each), a
// Newton/bisection iteration (median 3-4 steps, at most 24, each ~50 flops and a sin/cos) and
// one 4-atom weight (~120 flops): ~1500-2500 flops. CPU (this test machine, float, one core):
// ~0.5-0.9 µs per bound, ~8x Hamburger 4MSM. Bounded loops, no recursion, fixed-size state:
// valid GLSL.
//
// Failure modes and accuracy.
//  (a) Moments outside the moment space (T indefinite after rounding or filtering) have no
//      meaning: bias them toward the uniform distribution (msm_trig_bias; T becomes
//      (1-α) T + α I, smallest eigenvalue >= α). Unbiased or garbage moments still give a finite
//      result in [0,1] (pivots floored, NaN mapped to 0), just not a meaningful one.
//  (b) Near 1-2 Dirac distributions T is nearly singular (pivots ~α) and the pivots cancel from
//      O(1) to ~α: the factorization runs in double-float (requires IEEE float operations: GLSL
//      `precise`, no -ffast-math in C++). Remaining float error against the LP on the same
//      moments: p99 ~5e-6, worst ~1e-3 inside the ~sqrt(α) wide transition where the bound
//      jumps at a nearly Dirac depth, or when the arc is so short (zf within ~0.01 of 0 or 1)
//      that all atoms cluster.
//  (c) The seam: z = 0 and z = 1 have the same moments. Occluders at depths below ~3e-3 are
//      partly taken for depths near 1 (light leaks from them; the upper bound mirrors this near
//      1). Keep the depth range of the shadow map away from 0 and 1.
//  (d) The bias blurs the bounds: for 1-2 Diracs, exact without it, the error is ~α/δ⁴ for
//      Diracs δ apart (median ~0.4α, p99 4e-4 with the default α in the test).
//  (e) Degenerate brackets (t and s within 1e-5 rad, or rounding that contradicts step 2) fall
//      back to the better canonical representation, an upper estimate of G by at most the
//      variation of f across the bracket.
//
// Precondition: b biased (msm_trig_bias) so that T is positive definite. zf <= 0 gives a lower
// bound of 0, zf > 1 gives 1; the upper bound is 0 for zf < 0 and 1 for zf >= 1.
#ifndef MSM_TRIGONOMETRIC_H
#define MSM_TRIGONOMETRIC_H
#include "msm/shared.h"

MSM_BEGIN

// Default bias strength toward the uniform distribution (all four trigonometric moments zero,
// T = I). The float rounding of the moments perturbs T by |δT| <~ 1e-7, so α must stay well
// above that; larger α blurs the bounds near Diracs (error ~α/δ⁴ for Diracs δ apart). 5e-6 is
// the measured compromise (see trigonometric_test.cpp). A bound for the biased moments is a
// bound for (1-α) Z + α U, which differs from the CDF of Z by at most α.
const float MSM_TRIG_ALPHA_DEFAULT = 5.0e-6f;
// Most Newton/bisection steps for the stationary point in its sub-bracket: Newton converges in
// ~3-5; bisection, where g is not monotone, needs up to ~19 to shrink 2π/8 to 2e-6.
const int MSM_TRIG_ITERATIONS = 24;
// Sub-intervals of the bracket scanned for the sign change of the stationarity function.
const int MSM_TRIG_SCAN = 8;
// Brackets narrower than this (rad) count as degenerate: in float, the atoms of nearly singular
// T are only this accurate, and the 4-atom weights inside such a bracket are rounding noise.
const float MSM_TRIG_MIN_BRACKET = 1.0e-5f;
// Floor of the pivots of T: far below α, so it only acts on unbiased boundary moments.
const float MSM_TRIG_MIN_PIVOT = 1.0e-10f;

// b' = (1 - α) b + α b*, b* = 0 (the uniform distribution on [0,1]).
MSM_FN vec4 msm_trig_bias(vec4 b, float alpha) { return (1.0f - alpha) * b; }
MSM_FN vec4 msm_trig_bias(vec4 b) { return msm_trig_bias(b, MSM_TRIG_ALPHA_DEFAULT); }

// --- complex numbers as vec2(re, im) ---
MSM_FN vec2 msm_trig_cmul(vec2 a, vec2 b) { return vec2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x); }
MSM_FN vec2 msm_trig_conj(vec2 a) { return vec2(a.x, -a.y); }
MSM_FN vec2 msm_trig_cdiv(vec2 a, vec2 b) { return msm_trig_cmul(a, msm_trig_conj(b)) / dot(b, b); }
MSM_FN vec2 msm_trig_cis(float t) { return vec2(cos(t), sin(t)); }
// Principal square root; the smaller component from the larger one (no cancellation in r ± x).
MSM_FN vec2 msm_trig_csqrt(vec2 z) {
  float t = sqrt(0.5f * (length(z) + abs(z.x)));
  if (t == 0.0f) return vec2(0.0f);
  float o = 0.5f * z.y / t;
  return z.x >= 0.0f ? vec2(t, o) : vec2(abs(o), z.y < 0.0f ? -t : t);
}
// Angle of z in [0, 2π).
MSM_FN float msm_trig_arg(vec2 z) {
  float a = atan(z.y, z.x);
  return a < 0.0f ? a + MSM_TWO_PI : a;
}

// Double-float arithmetic: msm_df_* and msm_two_product of msm/eft.h (through shared.h).

// T = L D Lᴴ for T = [[1, c1, c2], [c̄1, 1, c1], [c̄2, c̄1, 1]]: L unit lower triangular with
// entries l10 = c̄1, l20 = c̄2, l21; D = diag(1, d1, d2). For nearly singular T (1-2 Diracs) the
// pivots are differences of O(1) terms that cancel down to ~α: d1, the numerator of l21 and
// det T = d1 d2 are evaluated in double-float (~44 bits) from the float moments, which makes the
// factorization as accurate as the moments themselves (in plain float it dominated the error).
struct TrigLdl {
  vec2 c1;
  vec2 c2;
  vec2 l21;
  float d1;
  float d2;
};

MSM_FN TrigLdl msm_trig_ldl(vec4 b) {
  float x1 = b[1], y1 = b[0], x2 = b[3], y2 = b[2];
  vec2 d1 = msm_df_sum_prod2(1.0f, -x1, x1, -y1, y1); // 1 - |c1|²
  vec2 nr = msm_df_sum_prod2(x1, -x2, x1, -y2, y1);   // Re(c̄1 - c̄2 c1)
  vec2 ni = msm_df_sum_prod2(-y1, -x2, y1, y2, x1);   // Im(c̄1 - c̄2 c1)
  vec2 a = msm_df_sum_prod2(1.0f, -x2, x2, -y2, y2);  // 1 - |c2|²
  vec2 n2 = msm_df_add(msm_df_mul(nr, nr), msm_df_mul(ni, ni));
  vec2 det = msm_df_add(msm_df_mul(a, d1), -n2); // (1 - |c2|²) d1 - |n|²
  // Pivots >= the smallest eigenvalue of T (>= α for biased moments); the floor only keeps
  // unbiased boundary moments (a missing bias) from dividing by zero.
  float pivot1 = max(d1.x + d1.y, MSM_TRIG_MIN_PIVOT);
  float pivot2 = max((det.x + det.y) / pivot1, MSM_TRIG_MIN_PIVOT);
  return TrigLdl(vec2(x1, y1), vec2(x2, y2), vec2(nr.x + nr.y, ni.x + ni.y) / pivot1, pivot1, pivot2);
}

// L⁻¹ r for r = (1, w̄, w̄²), |w| = 1: returns y1 and y2 (y0 = 1).
struct TrigForward {
  vec2 y1;
  vec2 y2;
};

MSM_FN TrigForward msm_trig_forward(TrigLdl f, vec2 w) {
  vec2 y1 = msm_trig_conj(w) - msm_trig_conj(f.c1);
  // w̄² - c̄2 cancels down to ~|w - atom| for w near a nearly Dirac atom: double-float.
  vec2 re = msm_df_sum_prod2(-f.c2.x, w.x, w.x, -w.y, w.y);
  vec2 im = msm_df_sum_prod2(f.c2.y, -2.0f * w.x, w.y, 0.0f, 0.0f);
  vec2 y2 = vec2(re.x + re.y, im.x + im.y) - msm_trig_cmul(f.l21, y1);
  return TrigForward(y1, y2);
}

// Christoffel function ρ(w) = 1 / (rᴴ T⁻¹ r): the largest mass any representation puts at w.
MSM_FN float msm_trig_christoffel(TrigLdl f, vec2 w) {
  TrigForward y = msm_trig_forward(f, w);
  return 1.0f / (1.0f + dot(y.y1, y.y1) / f.d1 + dot(y.y2, y.y2) / f.d2);
}

// The two atoms other than ξ of the canonical representation through ξ: the roots of
// h2 w² + h1 w + h0 with h = T⁻¹ (1, ξ̄, ξ̄²), as angles in [0, 2π) measured from the point o.
MSM_FN vec2 msm_trig_canonical_atoms(TrigLdl f, vec2 xi, vec2 o) {
  TrigForward y = msm_trig_forward(f, xi);
  vec2 h2 = y.y2 / f.d2;
  vec2 h1 = y.y1 / f.d1 - msm_trig_cmul(msm_trig_conj(f.l21), h2);
  vec2 h0 = vec2(1.0f, 0.0f) - msm_trig_cmul(f.c1, h1) - msm_trig_cmul(f.c2, h2);
  // Stable quadratic formula: q = -(h1 + sgn sqrt(disc)) / 2, roots q / h2 and h0 / q; only
  // the arguments are needed (the roots lie on the unit circle).
  vec2 sq = msm_trig_csqrt(msm_trig_cmul(h1, h1) - 4.0f * msm_trig_cmul(h2, h0));
  if (dot(h1, sq) < 0.0f) sq = -sq;
  vec2 q = -0.5f * (h1 + sq);
  vec2 oc = msm_trig_conj(o);
  return vec2(msm_trig_arg(msm_trig_cmul(msm_trig_cmul(q, msm_trig_conj(h2)), oc)),
              msm_trig_arg(msm_trig_cmul(msm_trig_cmul(h0, msm_trig_conj(q)), oc)));
}

// Weight of atom a in the 3-atom representation {a, p, q} (a canonical representation):
// E(w⁻¹ (w-p)(w-q)) a / ((a-p)(a-q)), Lagrange interpolation with c_{-1}, c0, c1. Unlike the
// Christoffel function, which peaks sharply (width ~sqrt(α)) at nearly Dirac atoms, this is
// insensitive to the rounding error of the atom positions.
MSM_FN float msm_trig_canonical_weight(vec2 c1, vec2 a, vec2 p, vec2 q) {
  vec2 num = c1 - (p + q) + msm_trig_cmul(msm_trig_cmul(p, q), msm_trig_conj(c1));
  return msm_trig_cdiv(msm_trig_cmul(num, a), msm_trig_cmul(a - p, a - q)).x;
}

// m_j = E(w^{j-2} (w - e0)(w - e1)), j = 0, 1, 2, for the arc ends e0, e1; S = e0 + e1, P = e0 e1.
struct TrigArcMoments {
  vec2 m0;
  vec2 m1;
  vec2 m2;
};

MSM_FN TrigArcMoments msm_trig_arc_moments(vec2 c1, vec2 c2, vec2 e0, vec2 e1) {
  vec2 S = e0 + e1, P = msm_trig_cmul(e0, e1);
  vec2 c1c = msm_trig_conj(c1);
  vec2 m0 = vec2(1.0f, 0.0f) - msm_trig_cmul(S, c1c) + msm_trig_cmul(P, msm_trig_conj(c2));
  vec2 m1 = c1 - S + msm_trig_cmul(P, c1c);
  vec2 m2 = c2 - msm_trig_cmul(S, c1) + P;
  return TrigArcMoments(m0, m1, m2);
}

// The fourth atom v of the representation with atoms e0, e1, u: v = (u m1 - m2) / (u m0 - m1).
MSM_FN vec2 msm_trig_fourth_atom(TrigArcMoments m, vec2 u) {
  vec2 v = msm_trig_cdiv(msm_trig_cmul(u, m.m1) - m.m2, msm_trig_cmul(u, m.m0) - m.m1);
  return v / length(v);
}

// Weight of atom a in the representation with atoms {a, p, q, r}: E(w⁻¹ Q(w)) a / Q(a) with
// Q(w) = (w - p)(w - q)(w - r) (Lagrange interpolation in the span of w^-1..w^2).
MSM_FN float msm_trig_atom_weight(vec2 c1, vec2 c2, vec2 a, vec2 p, vec2 q, vec2 r) {
  vec2 pq = msm_trig_cmul(p, q);
  vec2 e1 = p + q + r;
  vec2 e2 = pq + msm_trig_cmul(p + q, r);
  vec2 e3 = msm_trig_cmul(pq, r);
  // E(w⁻¹ (w³ - e1 w² + e2 w - e3)) = c2 - e1 c1 + e2 - e3 c̄1
  vec2 num = c2 - msm_trig_cmul(e1, c1) + e2 - msm_trig_cmul(e3, msm_trig_conj(c1));
  vec2 den = msm_trig_cmul(msm_trig_cmul(a - p, a - q), a - r);
  return msm_trig_cdiv(msm_trig_cmul(num, a), den).x;
}

// The stationarity function g (the sign of f') and its derivative in x, u = e^{ix} on the circle.
MSM_FN vec2 msm_trig_stationarity(TrigArcMoments m, vec2 e0, vec2 e1, vec2 u, bool two_in_arc) {
  if (!two_in_arc) {
    // g_A = Im(P̄ (2 m0 u² - (2 m1 + S m0) u)) = Im(A u² + B u)
    vec2 Pc = msm_trig_conj(msm_trig_cmul(e0, e1));
    vec2 A = 2.0f * msm_trig_cmul(Pc, m.m0);
    vec2 B = -msm_trig_cmul(Pc, 2.0f * m.m1 + msm_trig_cmul(e0 + e1, m.m0));
    vec2 Au2 = msm_trig_cmul(A, msm_trig_cmul(u, u));
    vec2 Bu = msm_trig_cmul(B, u);
    return vec2(Au2.y + Bu.y, 2.0f * Au2.x + Bu.x);
  }
  // g_B = |e0-u|² |L1|² - |e1-u|² |L2|² with L1, L2 = L_0, L_1 of the top comment
  vec2 a1 = msm_trig_cmul(e0, m.m0) - m.m1, b1 = m.m2 - msm_trig_cmul(e0, m.m1);
  vec2 a2 = msm_trig_cmul(e1, m.m0) - m.m1, b2 = m.m2 - msm_trig_cmul(e1, m.m1);
  vec2 a1u = msm_trig_cmul(a1, u), a2u = msm_trig_cmul(a2, u);
  vec2 L1 = a1u + b1, L2 = a2u + b2;
  vec2 r0 = msm_trig_cmul(u, msm_trig_conj(e0)), r1 = msm_trig_cmul(u, msm_trig_conj(e1));
  float n1 = 2.0f - 2.0f * r0.x, n2 = 2.0f - 2.0f * r1.x;      // |e_k - u|²
  float dn1 = 2.0f * r0.y, dn2 = 2.0f * r1.y;                  // their derivatives in x
  float dL1 = -2.0f * msm_trig_cmul(msm_trig_conj(L1), a1u).y; // d/dx |L1|²
  float dL2 = -2.0f * msm_trig_cmul(msm_trig_conj(L2), a2u).y;
  float q1 = dot(L1, L1), q2 = dot(L2, L2);
  return vec2(n1 * q1 - n2 * q2, dn1 * q1 + n1 * dL1 - dn2 * q2 - n2 * dL2);
}

// inf μ(open arc from e0 counterclockwise to e1) over the measures with the factorized moments,
// for the arc length L = arg(e1 / e0) in (0, 2π] (L = 2π: the circle without e0).
MSM_FN float msm_trig_lower_arc(TrigLdl f, vec2 e0, vec2 e1, float L) {
  if (L >= MSM_TWO_PI) return msm_saturate(1.0f - msm_trig_christoffel(f, e0));
  vec2 tp = msm_trig_canonical_atoms(f, e1, e0); // σ_end, angles from e0
  vec2 t0 = msm_trig_canonical_atoms(f, e0, e0); // σ_start
  bool p1 = tp.x > 0.0f && tp.x<L, p2 = tp.y> 0.0f && tp.y < L;
  bool z1 = t0.x > 0.0f && t0.x<L, z2 = t0.y> 0.0f && t0.y < L;
  if (!(p1 || p2) || !(z1 || z2)) return 0.0f; // σ_end or σ_start has no mass in the arc
  bool two = p1 && p2, two0 = z1 && z2;
  // t and s: the first arc atoms of σ_end and σ_start, the ends of the bracket (t <= s in
  // exact arithmetic; paired by rank, not by comparing angles, which rounding may swap).
  float t = p1 ? (p2 ? min(tp.x, tp.y) : tp.x) : tp.y;
  float s = z1 ? (z2 ? min(t0.x, t0.y) : t0.x) : t0.y;
  // Weight in the arc of σ_end and σ_start (one atom in it: its weight; two: 1 - the weight
  // at the arc end).
  vec2 a1 = msm_trig_cmul(e0, msm_trig_cis(tp.x)), a2 = msm_trig_cmul(e0, msm_trig_cis(tp.y));
  vec2 b1 = msm_trig_cmul(e0, msm_trig_cis(t0.x)), b2 = msm_trig_cmul(e0, msm_trig_cis(t0.y));
  float g_end = two ? 1.0f - msm_trig_canonical_weight(f.c1, e1, a1, a2)
                    : msm_trig_canonical_weight(f.c1, p1 ? a1 : a2, p1 ? a2 : a1, e1);
  float g_start = two0 ? 1.0f - msm_trig_canonical_weight(f.c1, e0, b1, b2)
                       : msm_trig_canonical_weight(f.c1, z1 ? b1 : b2, z1 ? b2 : b1, e0);
  // Both are representations, so both are >= G; the smaller one is the answer when the
  // minimum of f lies at an end of the bracket, and the fallback for a degenerate bracket
  // (t = s up to the rounding of the atoms) or atom counts that differ (rounding at an arc end).
  float best = min(g_end, g_start);
  if (two != two0 || !(s > t + MSM_TRIG_MIN_BRACKET)) return msm_saturate(best);
  // g has the sign of f'. Scan for its first change from - to + (the minimum of f), which is
  // more robust than the signs at the ends alone: g vanishes at an end where an atom meets
  // another one (a nearly Dirac distribution), and rounding may flip its sign there.
  TrigArcMoments m = msm_trig_arc_moments(f.c1, f.c2, e0, e1);
  float lo = t, hi = t, glo = 0.0f, ghi = 0.0f;
  vec2 u_k = msm_trig_cmul(e0, msm_trig_cis(t));
  vec2 rotation = msm_trig_cis((s - t) / float(MSM_TRIG_SCAN));
  float x_prev = t, g_prev = msm_trig_stationarity(m, e0, e1, u_k, two).x;
  bool found = false;
  for (int k = 1; k <= MSM_TRIG_SCAN; ++k) {
    u_k = msm_trig_cmul(u_k, rotation);
    float x = k == MSM_TRIG_SCAN ? s : t + (s - t) * (float(k) / float(MSM_TRIG_SCAN));
    float g = msm_trig_stationarity(m, e0, e1, u_k, two).x;
    if (g_prev < 0.0f && g > 0.0f) {
      lo = x_prev, hi = x, glo = g_prev, ghi = g;
      found = true;
      break;
    }
    x_prev = x, g_prev = g;
  }
  if (!found) return msm_saturate(best);
  // Safeguarded Newton on g in [lo, hi], g(lo) < 0 < g(hi), from the regula falsi point:
  // Newton steps where they stay inside the bracket, bisection otherwise (g need not be
  // monotone in the bracket). Ends when a step is below 2e-6 rad: the error of f is second
  // order in the error of x at the minimum.
  float x = lo - glo * (hi - lo) / (ghi - glo);
  for (int i = 0; i < MSM_TRIG_ITERATIONS; ++i) {
    vec2 g = msm_trig_stationarity(m, e0, e1, msm_trig_cmul(e0, msm_trig_cis(x)), two);
    if (g.x < 0.0f)
      lo = x;
    else
      hi = x;
    float next = x - g.x / g.y;
    if (!(next > lo && next < hi)) next = 0.5f * (lo + hi);
    float step = abs(next - x);
    x = next;
    if (step <= 2.0e-6f) break;
  }
  vec2 u = msm_trig_cmul(e0, msm_trig_cis(x));
  vec2 v = msm_trig_fourth_atom(m, u);
  float shadow = msm_trig_atom_weight(f.c1, f.c2, u, e0, e1, v);
  if (two) shadow += msm_trig_atom_weight(f.c1, f.c2, v, e0, e1, u);
  return msm_saturate(min(best, shadow));
}

// Sharp lower bound of Z(z < zf): inf μ(open arc (0, 2π zf)).
MSM_FN float msm_trig_lower_from_ldl(TrigLdl f, float zf) {
  if (zf <= 0.0f) return 0.0f;
  if (zf > 1.0f) return 1.0f;
  float phi = MSM_TWO_PI * zf;
  return msm_trig_lower_arc(f, vec2(1.0f, 0.0f), msm_trig_cis(phi), phi);
}

// Sharp upper bound of Z(z <= zf) = 1 - inf μ(open arc (2π zf, 2π)).
MSM_FN float msm_trig_upper_from_ldl(TrigLdl f, float zf) {
  if (zf < 0.0f) return 0.0f;
  if (zf >= 1.0f) return 1.0f;
  float phi = MSM_TWO_PI * zf;
  return msm_saturate(1.0f - msm_trig_lower_arc(f, msm_trig_cis(phi), vec2(1.0f, 0.0f), MSM_TWO_PI - phi));
}

// Sharp lower bound of Z(z < zf) for biased trigonometric moments b (see top of file).
MSM_FN float msm_trig_lower(vec4 b, float zf) { return msm_trig_lower_from_ldl(msm_trig_ldl(b), zf); }

// Sharp upper bound of Z(z <= zf) for biased trigonometric moments b.
MSM_FN float msm_trig_upper(vec4 b, float zf) { return msm_trig_upper_from_ldl(msm_trig_ldl(b), zf); }

// Both bounds with one factorization: (lower of Z(z < zf), upper of Z(z <= zf)).
MSM_FN vec2 msm_trig_bounds(vec4 b, float zf) {
  TrigLdl f = msm_trig_ldl(b);
  return vec2(msm_trig_lower_from_ldl(f, zf), msm_trig_upper_from_ldl(f, zf));
}

MSM_END

#endif // MSM_TRIGONOMETRIC_H
