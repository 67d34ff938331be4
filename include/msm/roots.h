// Polynomials shared by the reconstructions, written to survive degenerate input: roots without
// cancellation, inf or NaN (roots escaping to infinity are clamped to ±MSM_ROOT_LIMIT; depths
// live in [-1,1], so the closed forms using the clamped root take their limits), and the weights
// of atoms in a distribution with known moments.
#ifndef MSM_ROOTS_H
#define MSM_ROOTS_H
#include "msm/shared.h"

MSM_BEGIN

const float MSM_ROOT_LIMIT = 1.0e8f;

// Largest finite float. A value x is finite iff |x| <= MSM_FLT_MAX: the comparison is false for
// NaN and ±inf, on the CPU and on a device alike (GLSL's isnan/isinf may be folded away).
const float MSM_FLT_MAX = 3.40282347e38f;
MSM_FN bool msm_is_finite(float x) { return abs(x) <= MSM_FLT_MAX; }
MSM_FN bool msm_is_finite4(vec4 v) {
  return msm_is_finite(v[0]) && msm_is_finite(v[1]) && msm_is_finite(v[2]) && msm_is_finite(v[3]);
}

// x where x > lo, else lo; NaN goes to lo. Floors values that may be NaN: GLSL leaves max() with
// a NaN operand undefined (GLM and std::max return whichever operand their comparison picks), and
// a NaN that survived a max() would make the CPU and a device disagree.
MSM_FN float msm_at_least(float x, float lo) { return x > lo ? x : lo; }

// Receivers at |zf| >= MSM_ROOT_LIMIT (or NaN) lie beyond every depth: the reconstructions return 1
// for zf >= MSM_ROOT_LIMIT and valid moments, else 0 (zf² would overflow their solves, and their
// closed forms use roots clamped to that limit).
MSM_FN bool msm_receiver_in_range(float zf) { return abs(zf) < MSM_ROOT_LIMIT; }
MSM_FN float msm_receiver_out_of_range_shadow(bool valid, float zf) { return (valid && zf > 0.0f) ? 1.0f : 0.0f; }

// x clamped to [-MSM_ROOT_LIMIT, MSM_ROOT_LIMIT]; NaN goes to -MSM_ROOT_LIMIT.
MSM_FN float msm_clamp_root(float x) {
  return x > -MSM_ROOT_LIMIT ? (x < MSM_ROOT_LIMIT ? x : MSM_ROOT_LIMIT) : -MSM_ROOT_LIMIT;
}

// Both real roots of c2 z² + c1 z + c0 (ascending), for c not all zero; a negative discriminant
// (rounding) counts as zero.
MSM_FN vec2 msm_solve_quadratic(vec3 c) {
  c /= max(max(abs(c[0]), abs(c[1])), abs(c[2]));
  float s = sqrt(max(c[1] * c[1] - 4.0f * c[0] * c[2], 0.0f));
  float t = -0.5f * (c[1] + (c[1] < 0.0f ? -s : s));
  t = (t == 0.0f) ? 1.0e-30f : t;
  float r1 = msm_clamp_root(c[0] / t);
  float r2 = msm_clamp_root(t / c[2]);
  return vec2(min(r1, r2), max(r1, r2));
}

// E[(z-u)(z-v)(z-t)] from the moments b = (b1, b2, b3, .) (b0 = 1).
MSM_FN float msm_expect_cubic(vec4 b, float u, float v, float t) {
  float e1 = u + v + t, e2 = u * v + u * t + v * t, e3 = u * v * t;
  return b[2] - e1 * b[1] + e2 * b[0] - e3;
}

// Weight of atom x in the distribution on the four atoms {x, u, v, t} that matches b0..b3:
// Lagrange interpolation, E[(z-u)(z-v)(z-t)] / ((x-u)(x-v)(x-t)). An atom coinciding with
// another (invalid input) gets weight 0 instead of inf or NaN.
MSM_FN float msm_four_atom_weight(vec4 b, float x, float u, float v, float t) {
  float denominator = (x - u) * (x - v) * (x - t);
  return (denominator != 0.0f) ? msm_expect_cubic(b, u, v, t) / denominator : 0.0f;
}

MSM_END

#endif // MSM_ROOTS_H
