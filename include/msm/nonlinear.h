// Non-linearly quantized moment shadow maps (HPG 2017 §3), depth in [-1,1].
//
// Four filtered float moments b = (b1, b2, b3, b4) are replaced by NonLinearMoments Φ(b) =
// (y1, y2, v2, ξ4): the two-atom distribution (1 - v2) δ(y1) + v2 δ(y2) that matches b0..b3
// (HPG Alg. 2, JCGT Alg. 2) and the offset ξ4 >= 0 of the fourth moment (HPG Eq. (1), (3)).
// Φ's input is the filtered float moment vector biased for float storage (b* = (0, 0.375, 0,
// 0.375), α = 3e-7: MSM_REP_SIGNED_FLOAT in bias.h; HPG §3.1, §3.2); msm_nl_from_filtered()
// applies that bias, msm_nl_from_moments() is Φ alone. Φ is then stored at
//  - 64 bits (RGBA16_UNORM, two uints): (y1 + 1) / 2, (y2 + 1) / 2, v2, Ψ4(ξ4), each rounded to
//    nearest as Vulkan's UNORM conversion does (HPG §3.3);
//  - 32 bits (R32_UINT): Ψ4(ξ4) in 6 bits rounded up, sqrt(v2) in 7 bits, and y1 <= y2 as two
//    10-bit depths folded into 19 bits (HPG §3.5). Layout, least significant bit first:
//        bits  0.. 9  (10 bits)  d2: ỹ2            if unfolded, 1022 - ỹ2 if folded (0..1022)
//        bits 10..18  ( 9 bits)  d1: ỹ1 (0..511)   if unfolded, 1023 - ỹ1 if folded (1..511)
//        bits 19..25  ( 7 bits)  round(127 sqrt(v2))
//        bits 26..31  ( 6 bits)  Ψ4 rounded up to a multiple of 1/63 (see msm_nl_psi4_encode6)
//    with ỹl = min(floor(511.5 (yl + 1)), 1022) in 0..1022, ỹ1 <= ỹ2. A pair with ỹ1 >= 512 is
//    folded (HPG Fig. 5): (ỹ1, ỹ2) -> (1023 - ỹ1, 1022 - ỹ2). Unfolded pairs have d1 <= d2
//    (ỹ1 <= ỹ2), folded pairs have d2 = 1022 - ỹ2 <= 1022 - ỹ1 = d1 - 1 < d1, so the decoder
//    reads the half from the order of the stored fields: d1 <= d2 unfolded, d1 > d2 folded.
//    (1023 · 1024 / 2 = 523776 ordered pairs <= 2^19.) Depths decode at the centers of their
//    bins, yl = (ỹl + 0.5) / 511.5 - 1.
// Shading uses HPG Algorithm 3 with the erratum (ERRATA.md: the ξ'4 term of w_l is divided).
// Where the 32-bit format loses accuracy in ξ4 it moves ξ4 up, never down, because a larger ξ4
// only lowers the lower bound (HPG Fig. 3): the clamp at MSM_NL_XI4_MIN and the 6-bit rounding
// of Ψ4 up. (The 64-bit format rounds Ψ4 to nearest, as the paper does: half a 16-bit step.)
#ifndef MSM_NONLINEAR_H
#define MSM_NONLINEAR_H
#include "msm/bias.h"
#include "msm/config.h"
#include "msm/hamburger4.h"
#include "msm/quantize.h"
#include "msm/shared.h"
#include "msm/three_moments.h"

MSM_BEGIN

struct NonLinearMoments {
  float y1;  // smaller depth, y1 <= y2, both in [-1,1] for distributions on [-1,1]
  float y2;  // larger depth
  float v2;  // weight of y2, in [0,1]; y1 has weight 1 - v2
  float xi4; // offset of the fourth moment, in [0, 0.25]
};

// ---- Φ (HPG Algorithm 2) ----
// Precondition: b biased (see above), so that σ² = b2 - b1² > 0. A non-positive σ² (a single
// depth, or rounding) gives δ(b1) with v2 = 0, as msm_two_depths_from_three_moments does, and
// ξ4 from the LDLᵀ with σ² floored at MSM_MIN_PIVOT1 (then ~0: clamped to >= 0).
// In exact arithmetic y1, y2 lie in [-1,1] and ξ4 >= 0 (HPG §3.1, §3.2). In float they do not
// quite: the float moment vector itself is off by rounding (ξ4 of the float moments, evaluated
// in double, goes down to about -3e-8), the float evaluation adds ~4e-8, and when σ² ~ α the
// depth of weight ~α (the one the bias adds) is ill conditioned and may leave [-1,1] by ~0.02
// (nonlinear_test measures these). So the result is clamped: y to [-1,1], ξ4 to >= 0. Both
// clamps only touch values that rounding produced.
// Non-finite moments (a NaN texel) become MSM_NL_FAR, all depth at the far plane y = 1: it reads
// as lit (0) for every receiver up to the far plane, unquantized, at 64 bits and at 32 bits alike
// (32 bits store y = 1 in the last depth bin, whose centre is 1 - 1/1023), as NaN moments read in
// every other representation (hamburger4.h). Before, the 64/32-bit round trip of NaN stored
// codes 0 (y1 = y2 = -1) and read 1.
const NonLinearMoments MSM_NL_FAR = NonLinearMoments(1.0f, 1.0f, 0.0f, 0.0f);
MSM_FN bool msm_nl_is_finite(NonLinearMoments m) { return msm_is_finite4(vec4(m.y1, m.y2, m.v2, m.xi4)); }

// Φ of moments about depth c, b = (E[y - c], E[(y - c)²], E[(y - c)³], E[(y - c)⁴]), its depths
// given about 0 (c = 0: Φ of the moments themselves). Only the depths depend on c: moving every
// depth by c multiplies the Hankel matrix by a unit triangular matrix on either side, which keeps
// the pivots of its LDLᵀ, ξ4 among them, and the weights. In float, moments about a depth near the
// distribution's mean keep what moments about 0 of a depth far from 0 cancel away (see
// msm_nl_bilinear).
MSM_FN NonLinearMoments msm_nl_from_moments_about(vec4 b, float c) {
  if (!msm_is_finite4(b) || !msm_is_finite(c)) return MSM_NL_FAR;
  // Steps 1-5: the two depths and the weight of the larger one.
  TwoDepths two = msm_two_depths_from_three_moments(vec3(b[0], b[1], b[2]));
  // Steps 6-7: third diagonal entry of the LDLᵀ factorization of the Hankel matrix (Eq. (3)),
  // ξ4 = b4 - b2² - L21² σ² with L21 σ² = b3 - b1 b2, shared with Hamburger 4MSM. Its
  // differences are formed with one rounding (msm_fma): 6x less error in ξ4 than separate
  // multiplies and subtractions (max 4e-8 instead of 2.3e-7 against double on the same float
  // moments), which matters because ξ4 is ~1e-7 for the most common texel, a single surface.
  float xi4 = msm_hankel3_ldl(b).D2;
  NonLinearMoments m = NonLinearMoments(clamp(two.z.x + c, -1.0f, 1.0f), clamp(two.z.y + c, -1.0f, 1.0f), two.w.y,
                                        msm_at_least(xi4, 0.0f));
  if (!msm_nl_is_finite(m)) return MSM_NL_FAR; // finite but overflowing garbage
  return m;
}
MSM_FN NonLinearMoments msm_nl_from_moments(vec4 b) { return msm_nl_from_moments_about(b, 0.0f); }

// Φ of filtered, unbiased float moments: applies the float bias of [-1,1] depth first.
MSM_FN NonLinearMoments msm_nl_from_filtered(vec4 b) {
  return msm_nl_from_moments(msm_apply_bias(b, msm_moment_bias(MSM_REP_SIGNED_FLOAT)));
}

// HPG Eq. (4) about depth c: the moments of (1 - v2) δ(y1 - c) + v2 δ(y2 - c), plus ξ4 in the
// fourth. Inverse of msm_nl_from_moments_about(·, c); c = 0 is Eq. (4) itself (msm_nl_moments_from).
MSM_FN vec4 msm_nl_moments_about(NonLinearMoments m, float c) {
  float v1 = 1.0f - m.v2;
  float y1 = m.y1 - c, y2 = m.y2 - c;
  float y1s = y1 * y1, y2s = y2 * y2;
  return vec4(v1 * y1 + m.v2 * y2, v1 * y1s + m.v2 * y2s, v1 * y1s * y1 + m.v2 * y2s * y2,
              v1 * y1s * y1s + m.v2 * y2s * y2s + m.xi4);
}
// HPG Eq. (4): b = (1 - v2) b(y1) + v2 b(y2) + (0, 0, 0, ξ4). Inverse of Φ (for tests, and for
// true bilinear filtering: msm_nl_bilinear).
MSM_FN vec4 msm_nl_moments_from(NonLinearMoments m) { return msm_nl_moments_about(m, 0.0f); }

// The mean depth of m, (1 - v2) y1 + v2 y2.
MSM_FN float msm_nl_mean(NonLinearMoments m) { return mix(m.y1, m.y2, m.v2); }

// Φ of the bilinear interpolation of four texels' distributions, f the weights along x (m00 to m10,
// m01 to m11) and y: each texel back to moments (Eq. (4)), those interpolated, Φ again, so that the
// non-linear maps filter as the other moment maps do (HPG §4.2 interpolates the four texels'
// shadow intensities instead). The moments are taken about the interpolated mean depth c: a texel
// of a single surface has ξ4 ~ 1e-7 and a second depth of weight ~1e-3 (the blur over a sloped
// surface), which its moments about 0 hold only as a cancellation of O(1) terms where the depth is
// far from 0; interpolated and put through Φ in float, those lose them (ξ4 clamped to 0, two
// depths a few 1e-3 apart at the receiver: isolated texels up to 0.64 dark on lit ground near a
// local light, where [-1,1] depth is near -1; NonLinear.BilinearLookupOfLitPlanes). About c the
// moments are O((y - c)²) and keep them.
MSM_FN NonLinearMoments msm_nl_bilinear(NonLinearMoments m00, NonLinearMoments m10, NonLinearMoments m01,
                                        NonLinearMoments m11, vec2 f) {
  float c = mix(mix(msm_nl_mean(m00), msm_nl_mean(m10), f.x), mix(msm_nl_mean(m01), msm_nl_mean(m11), f.x), f.y);
  vec4 b = mix(mix(msm_nl_moments_about(m00, c), msm_nl_moments_about(m10, c), f.x),
               mix(msm_nl_moments_about(m01, c), msm_nl_moments_about(m11, c), f.x), f.y);
  return msm_nl_from_moments_about(b, c);
}

// ---- Ψ4: the warp of ξ4 to [0,1] (HPG §3.3) ----
// Ψ4(ξ4) = (ln ln(max(ξmin, ξ4) · 1e7) - ln ln(ξmin · 1e7)) / (ln ln(ξmax · 1e7) - ln ln(ξmin · 1e7))
// with ξmin = 1.2e-7, ξmax = 0.25 (config.h): ln ln(1.2) = -1.70198336, ln ln(2.5e6) = 2.69000851.
const float MSM_NL_XI4_SCALE = 1.0e7f;
const float MSM_NL_PSI4_LO = log(log(MSM_NL_XI4_MIN * MSM_NL_XI4_SCALE));
const float MSM_NL_PSI4_HI = log(log(MSM_NL_XI4_MAX * MSM_NL_XI4_SCALE));

// Monotone; Ψ4(ξ4 <= ξmin) = 0, Ψ4(ξmax) = 1; larger ξ4 saturate to 1.
MSM_FN float msm_nl_psi4(float xi4) {
  float l = log(log(max(MSM_NL_XI4_MIN, xi4) * MSM_NL_XI4_SCALE));
  return msm_saturate((l - MSM_NL_PSI4_LO) / (MSM_NL_PSI4_HI - MSM_NL_PSI4_LO));
}
// Inverse on [0,1]: ξ4 = exp(exp(Ψ4 (hi - lo) + lo)) / 1e7, in [ξmin, ξmax].
MSM_FN float msm_nl_psi4_inverse(float psi4) {
  float l = msm_saturate(psi4) * (MSM_NL_PSI4_HI - MSM_NL_PSI4_LO) + MSM_NL_PSI4_LO;
  return exp(exp(l)) * (1.0f / MSM_NL_XI4_SCALE);
}

// ---- 64 bits: four 16-bit UNORM (HPG §3.3) ----
MSM_FN uvec2 msm_nl_pack64(NonLinearMoments m) {
  if (!msm_nl_is_finite(m)) m = MSM_NL_FAR;
  return msm_pack_unorm16x4(vec4(0.5f * m.y1 + 0.5f, 0.5f * m.y2 + 0.5f, m.v2, msm_nl_psi4(m.xi4)));
}
MSM_FN NonLinearMoments msm_nl_unpack64(uvec2 p) {
  vec4 u = msm_unpack_unorm16x4(p);
  return NonLinearMoments(2.0f * u[0] - 1.0f, 2.0f * u[1] - 1.0f, u[2], msm_nl_psi4_inverse(u[3]));
}
// What a texture write then read does to m.
MSM_FN NonLinearMoments msm_nl_quantize64(NonLinearMoments m) { return msm_nl_unpack64(msm_nl_pack64(m)); }

// ---- 32 bits: one uint (HPG §3.5), layout at the top of this file ----
const uint MSM_NL32_DEPTH_MAX = 1022u; // ỹ in 0..1022

// ỹ = floor(511.5 (y + 1)), y clamped to [-1,1] and y = 1 put into the last bin 1022.
MSM_FN uint msm_nl_depth10_encode(float y) {
  return uint(min(floor(511.5f * (clamp(y, -1.0f, 1.0f) + 1.0f)), 1022.0f));
}
// Center of bin ỹ: (ỹ + 0.5) / 511.5 - 1 = (2 ỹ + 1) / 1023 - 1.
MSM_FN float msm_nl_depth10_decode(uint t) { return float(2u * t + 1u) * (1.0f / 1023.0f) - 1.0f; }

// (ỹ1, ỹ2) with ỹ1 <= ỹ2 <= 1022 -> the 19-bit pair code d2 | (d1 << 10) (HPG Fig. 5).
MSM_FN uint msm_nl_fold_depths(uvec2 t) {
  bool folded = t.x >= 512u;
  uint d1 = folded ? 1023u - t.x : t.x;
  uint d2 = folded ? 1022u - t.y : t.y;
  return d2 | (d1 << 10u);
}
// Inverse of msm_nl_fold_depths: d1 <= d2 means unfolded, d1 > d2 folded.
MSM_FN uvec2 msm_nl_unfold_depths(uint code) {
  uint d2 = code & 1023u;
  uint d1 = (code >> 10u) & 511u;
  return d1 <= d2 ? uvec2(d1, d2) : uvec2(1023u - d1, 1022u - d2);
}

// Ψ4 in 6 bits, rounded up: the stored q is the least q with decode(q) = q/63 >= Ψ4, so the
// decoded Ψ4 is never below the true one and ξ4 only grows (by less than one step, 1/63, in Ψ4).
// Ψ4 = 0, the most common value, stays exactly 0. ceil(Ψ4 · 63) can be one off where the float
// product rounded across an integer, so the encoder checks its neighbor with the decoder's own
// float expression. Decoding needs no correction: the rounding up happened on the way in.
MSM_FN float msm_nl_psi4_decode6(uint q) { return float(q) * (1.0f / 63.0f); }
MSM_FN uint msm_nl_psi4_encode6(float psi4) {
  float p = msm_saturate(psi4);
  uint q = uint(ceil(p * 63.0f)); // 0..63
  if (q > 0u && msm_nl_psi4_decode6(q - 1u) >= p)
    q -= 1u;
  else if (msm_nl_psi4_decode6(q) < p)
    q += 1u;
  return min(q, 63u);
}

MSM_FN uint msm_nl_pack32(NonLinearMoments m) {
  if (!msm_nl_is_finite(m)) m = MSM_NL_FAR;
  uint t1 = msm_nl_depth10_encode(m.y1);
  uint t2 = msm_nl_depth10_encode(m.y2);
  uint pair = msm_nl_fold_depths(uvec2(min(t1, t2), max(t1, t2)));
  uint v = uint(floor(sqrt(msm_saturate(m.v2)) * 127.0f + 0.5f));
  uint psi = msm_nl_psi4_encode6(msm_nl_psi4(m.xi4));
  return pair | (v << 19u) | (psi << 26u);
}
MSM_FN NonLinearMoments msm_nl_unpack32(uint p) {
  uvec2 t = msm_nl_unfold_depths(p & 0x7FFFFu);
  float s = float((p >> 19u) & 127u) * (1.0f / 127.0f);
  return NonLinearMoments(msm_nl_depth10_decode(t.x), msm_nl_depth10_decode(t.y), s * s,
                          msm_nl_psi4_inverse(msm_nl_psi4_decode6(p >> 26u)));
}
MSM_FN NonLinearMoments msm_nl_quantize32(NonLinearMoments m) { return msm_nl_unpack32(msm_nl_pack32(m)); }

// ---- Shading: HPG Algorithm 3 with the erratum ----
// Sharp lower bound of Z(z < zf) for the moments of Eq. (4), i.e. Hamburger 4MSM
// (msm_hamburger4_lower) on msm_nl_moments_from(m), without forming the moments.
// The degenerate inputs y1 = y2, v2 = 0, v2 = 1 (zero variance) are clamped away by
// MSM_NL_TOLERANCE (HPG §3.4), and ξ4 by MSM_NL_XI4_SHADING_MIN.
// ξ4 = 0 would make ξ'4 = 0 and w_l = 1 / (... + 0/0). The floor only has to keep ξ'4 > 0: decoded
// inputs have ξ4 >= MSM_NL_XI4_MIN anyway, and unquantized ones keep their own ξ4 (clamping them
// at MSM_NL_XI4_MIN too raised the mean difference to float MSM from 1.2e-5 to 4.3e-5 and the max
// from 0.11 to 0.29, all near steep steps). With it, ξ'4 >= 1e-12 / 16 and the terms of w_l stay
// far inside float range.
const float MSM_NL_XI4_SHADING_MIN = 1.0e-12f;
MSM_FN float msm_nl_shadow(NonLinearMoments m, float zf) {
  if (!msm_nl_is_finite(m)) return 0.0f; // as MSM_NL_FAR, and no NaN reaches the max() below
  float y1 = m.y1;
  float y2 = max(m.y2, y1 + MSM_NL_TOLERANCE);
  float v2 = clamp(m.v2, MSM_NL_TOLERANCE, 1.0f - MSM_NL_TOLERANCE);
  if (!(zf > y1)) return 0.0f; // NaN zf reads lit too
  // Shift and scale depths so that y1 = 0, y2 = 1; ξ4 scales with the fourth power.
  float inv_range = 1.0f / (y2 - y1);
  float zf1 = (zf - y1) * inv_range; // z'f in (0, 1] when zf <= y2
  float inv_range2 = inv_range * inv_range;
  float xi = max(m.xi4, MSM_NL_XI4_SHADING_MIN) * (inv_range2 * inv_range2); // ξ'4
  bool between = zf <= y2;
  float zl = zf1;
  if (between) {
    // The paper's q0 and q1 of the monic z² + q1 z + q0, whose smaller root is z1. q1 has a
    // pole at z'f = 1 (zf = y2), so the polynomial is multiplied by (1 - z'f) >= 0 first:
    // a z² + b z + c with a = 1 - z'f, b = (1 - z'f) q1, c = (1 - z'f) q0 <= 0. Its smaller
    // root is the non-positive one; each branch avoids cancellation, and at z'f = 1 (a = 0,
    // b = -ξ'4 / v2 < 0) it is the exact 0.
    float q0 = -xi / ((1.0f - v2) * zf1);
    float a = 1.0f - zf1;
    float b = -q0 * (v2 - zf1) / v2 - a;
    float c = q0 * a;
    float d = sqrt(max(b * b - 4.0f * a * c, 0.0f));
    zl = b <= 0.0f ? (2.0f * c) / (d - b) : (-b - d) / (2.0f * a);
  }
  // w_l = 1 / (p(zl)ᵀ B⁻¹ p(zl)) with B = M diag(1 - v2, v2, ξ'4) Mᵀ (ERRATA.md).
  float u = 1.0f - zl;
  float wl = 1.0f / (u * u / (1.0f - v2) + zl * zl / v2 + (u * u) * (zl * zl) / xi);
  return msm_saturate(between ? wl : 1.0f - wl);
}

MSM_END

#endif // MSM_NONLINEAR_H
