// Hamburger four-moment shadow mapping: the sharp bounds of Z(z < zf) over all distributions on
// the real line with moments (1, b1, b2, b3, b4) (2015 Alg. 2/3, JCGT Alg. 1 with m = 4).
// Precondition for every function: b is biased (bias.h), so the Hankel matrix
// B = [[1,b1,b2],[b1,b2,b3],[b2,b3,b4]] is positive definite; depth convention is the caller's.
#ifndef MSM_HAMBURGER4_H
#define MSM_HAMBURGER4_H
#include "msm/roots.h"
#include "msm/shared.h"

MSM_BEGIN

// The canonical representation through zf: B c = (1, zf, zf²) solved by LDLᵀ (robust for
// nearly singular B, 2015 §4.2); z2 <= z3 are the roots of c2 z² + c1 z + c0.
//
// Degenerate input. A kernel holding a single depth (a flat receiver: the most common kernel)
// gives a B that is singular up to the bias, and in float D2 = b4 - b2² - L21² D1 cancels to
// the size of its own rounding. The steps below reach a well-defined answer without inf or NaN:
//  - D1 = b2 - b1² (the variance) is floored at MSM_MIN_PIVOT1, orders of magnitude below what a
//    biased vector has (D1 >= α Var(b*) >= 1.1e-7; measured >= 4.3e-7 over every storage path),
//    so that L21 stays finite; a vector with D1 <= MSM_MIN_PIVOT1 or a non-finite component is
//    no biased texel's (e.g. a NaN texel stored as UNORM code 0 decodes to D1 = -0.49): it is
//    INVALID (msm_hamburger4_valid) and reads as lit, see msm_hamburger4_roots;
//  - D2 is floored at msm_hamburger4_min_d2(b) = 2^-24 |b4| (at least MSM_MIN_PIVOT2): one unit
//    roundoff of b4, the largest term of its cancelling difference (b2² <= b4 and L21² D1 <= b4),
//    each rounded to float at least once. A D2 below that is not resolved by float moments: the
//    rounded vector may even lie outside the moment space (D2 < 0 in exact arithmetic: 8.8% of
//    biased single depths in [0,1] float, where the 2015 b* = ½δ0 + ½δ1 has D2(b*) = 0). Why this
//    floor and not a tiny one (1e-12 before): with D2 -> 0 the bound becomes that of the two-atom
//    distribution fitted to b0..b3, whose atoms the rounding has moved. For two depths 5e-4 apart
//    (a receiver on them) that limit read 1 where PCF reads 0.4-0.5, darker than any distribution
//    with these moments (and the sharp bound of the exactly biased vector) allows. A larger D2
//    only lowers the lower bound (HPG §3.2, Fig. 3; nonlinear_test), so the floor returns the
//    bound of the most spread vector within one rounding of the input: the light side, never
//    darker than the moments allow. Its cost is nil where the bias already protects D2 (the
//    JCGT b* of [-1,1] depth: D2 >= α D2(b*) = α 0.234 >= 7e-8) and a receiver-side transition no
//    wider than the bias's for [0,1] depth (results.md, "Edges of the math"). HPG §3.3 clamps ξ4
//    = D2 at 1.2e-7 (2^-23 of [-1,1] moments) for the same reason: below it nothing changes;
//  - c is scaled to max |c_i| = 1 (roots are scale-free) and the quadratic is solved without
//    cancellation (t = -(c1 + sign(c1) √disc)/2; roots c0/t and t/c2);
//  - a root escaping to infinity (c2 -> 0, 2015 Prop. 3) is clamped to ±MSM_ROOT_LIMIT, where the
//    closed forms below take their limits to float precision.
struct Hamburger4Roots {
  vec3 c;
  float z2;
  float z3;
};

// B = [[1,b1,b2],[b1,b2,b3],[b2,b3,b4]] = L D Lᵀ with L = [[1,0,0],[b1,1,0],[b2,L21,1]] and
// D = diag(1, D1, D2). D1 is the variance; D2 = det B / D1 is ξ4 of the non-linear
// representation (HPG Eq. (3)). The differences cancel to ~α for biased moments, so each is formed
// with one rounding (msm_fma). D1 is floored at MSM_MIN_PIVOT1 so that L21 stays finite; D2 is
// returned as computed (callers floor or clamp it as they need).
struct HankelLdl3 {
  float D1;
  float L21;
  float L21D1;
  float D2;
};

// Floors of the pivots D1 and D2 (see the top of this file).
const float MSM_MIN_PIVOT1 = 1.0e-10f;
const float MSM_MIN_PIVOT2 = 1.0e-12f;
// 2^-24: the unit roundoff of float, the relative rounding of every stored moment.
const float MSM_FLOAT_ROUNDING = 5.96046448e-8f;

MSM_FN HankelLdl3 msm_hankel3_ldl(vec4 b) {
  float b1 = b[0], b2 = b[1], b3 = b[2], b4 = b[3];
  float D1 = msm_at_least(msm_fma(-b1, b1, b2), MSM_MIN_PIVOT1);
  float L21D1 = msm_fma(-b1, b2, b3);
  float L21 = L21D1 / D1;
  return HankelLdl3(D1, L21, L21D1, msm_fma(-L21, L21D1, msm_fma(-b2, b2, b4)));
}

// A vector that some biased texel can have: finite, with variance above MSM_MIN_PIVOT1.
MSM_FN bool msm_hamburger4_valid(vec4 b) { return msm_is_finite4(b) && msm_fma(-b[0], b[0], b[1]) > MSM_MIN_PIVOT1; }

// The smallest D2 that float moments resolve (see above).
MSM_FN float msm_hamburger4_min_d2(vec4 b) { return msm_at_least(MSM_FLOAT_ROUNDING * abs(b[3]), MSM_MIN_PIVOT2); }

// Invalid input (msm_hamburger4_valid false) or a receiver out of range comes back as c = 0 and
// both roots at +MSM_ROOT_LIMIT: the bounds below then read 0 (lit), or 1 behind everything, and
// w0 = 0.
MSM_FN Hamburger4Roots msm_hamburger4_roots(vec4 b, float zf) {
  if (!(msm_hamburger4_valid(b) && msm_receiver_in_range(zf)))
    return Hamburger4Roots(vec3(0.0f), MSM_ROOT_LIMIT, MSM_ROOT_LIMIT);
  float b1 = b[0], b2 = b[1];
  HankelLdl3 f = msm_hankel3_ldl(b);
  float D1 = f.D1, L21 = f.L21;
  float D2 = msm_at_least(f.D2, msm_hamburger4_min_d2(b));
  // Forward substitution, scaling, back substitution.
  float y1 = zf - b1;
  float y2 = msm_fma(-L21, y1, msm_fma(zf, zf, -b2));
  y1 /= D1;
  y2 /= D2;
  vec3 c;
  c[2] = y2;
  c[1] = y1 - L21 * c[2];
  c[0] = 1.0f - b1 * c[1] - b2 * c[2];
  vec2 z = msm_solve_quadratic(c);
  return Hamburger4Roots(c, z.x, z.y);
}

// Weight of zf in the canonical representation: w0 = 1 / (pᵀ B⁻¹ p), p = (1, zf, zf²)
// (2015 supplementary, Proposition 10). pᵀ B⁻¹ p >= 1 for positive definite B (w0 <= 1); rounding
// just below 1 gives 1, and a non-positive or NaN value (invalid input, c = 0) gives 0, so that
// lower <= lower + w0 always holds.
MSM_FN float msm_hamburger4_w0(Hamburger4Roots r, float zf) {
  float q = r.c[0] + zf * (r.c[1] + zf * r.c[2]);
  return q >= 1.0f ? 1.0f / q : (q > 0.0f ? 1.0f : 0.0f);
}

// Sharp lower bound of Z(z < zf) with the closed forms of 2015 Algorithm 3, steps 3-6.
MSM_FN float msm_hamburger4_lower_from_roots(vec4 b, float zf, Hamburger4Roots r) {
  if (!msm_receiver_in_range(zf)) return msm_receiver_out_of_range_shadow(msm_hamburger4_valid(b), zf);
  float b1 = b[0], b2 = b[1];
  float z2 = r.z2, z3 = r.z3;
  if (zf <= z2) return 0.0f;
  if (zf <= z3) return msm_saturate((zf * z3 - b1 * (zf + z3) + b2) / ((z3 - z2) * (zf - z2)));
  return msm_saturate(1.0f - (z2 * z3 - b1 * (z2 + z3) + b2) / ((zf - z2) * (zf - z3)));
}

MSM_FN float msm_hamburger4_lower(vec4 b, float zf) {
  return msm_hamburger4_lower_from_roots(b, zf, msm_hamburger4_roots(b, zf));
}

// Both bounds at once: (lower, upper), lower <= upper for any input (w0 >= 0).
MSM_FN vec2 msm_hamburger4_bounds(vec4 b, float zf) {
  Hamburger4Roots r = msm_hamburger4_roots(b, zf);
  float lower = msm_hamburger4_lower_from_roots(b, zf, r);
  return vec2(lower, msm_saturate(lower + msm_hamburger4_w0(r, zf)));
}

// Sharp upper bound of Z(z <= zf): lower bound plus the weight of zf (JCGT §5.3, Fig. 2).
MSM_FN float msm_hamburger4_upper(vec4 b, float zf) { return msm_hamburger4_bounds(b, zf).y; }

// The whole canonical distribution w0 δ(zf) + w1 δ(z[1]) + w2 δ(z[2]), z[1] <= z[2]: what the
// blocker search (blocker.h) averages. Weights from Lagrange interpolation on b0, b1, b2.
struct Canonical4 {
  vec3 z; // (zf, z2, z3)
  vec3 w;
};

MSM_FN Canonical4 msm_hamburger4_canonical(vec4 b, float zf) {
  // Invalid input (see msm_hamburger4_roots): no atom besides zf, every weight 0.
  if (!(msm_hamburger4_valid(b) && msm_receiver_in_range(zf)))
    return Canonical4(vec3(zf, MSM_ROOT_LIMIT, MSM_ROOT_LIMIT), vec3(0.0f));
  Hamburger4Roots r = msm_hamburger4_roots(b, zf);
  float b1 = b[0], b2 = b[1];
  float z2 = r.z2, z3 = r.z3;
  // Coincident nodes (a double root) get weight 0, not 0/0.
  float d1 = (z2 - zf) * (z2 - z3), d2 = (z3 - zf) * (z3 - z2);
  float w1 = d1 != 0.0f ? (b2 - b1 * (zf + z3) + zf * z3) / d1 : 0.0f;
  float w2 = d2 != 0.0f ? (b2 - b1 * (zf + z2) + zf * z2) / d2 : 0.0f;
  return Canonical4(vec3(zf, z2, z3), vec3(msm_hamburger4_w0(r, zf), w1, w2));
}

MSM_END

#endif // MSM_HAMBURGER4_H
