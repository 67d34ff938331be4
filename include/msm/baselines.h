// The filterable shadow maps that moment shadow mapping is compared against (2015 §2, §3;
// JCGT §2.2), each as a GENERATION function (what one texel stores for occluder depth z, before
// any filtering) and a RECONSTRUCTION function (the shadow intensity, an estimate of Z(z < zf)
// from one filtered texel b = E_Z(b(z)) and the fragment depth zf).
//
//   technique       stores b(z)                              reconstruction           lower bound
//   VSM             (z, z²)                                  Cantelli                 sharp, I = R
//   ESM             exp(c z)                                 Markov                   sharp, I = R
//   EVSM2 / EVSM4   (w, w²) for w = exp(c+ z) [and -exp(-c- z)]  Cantelli per warp, max  yes, not sharp
//   CSM             sin/cos((2k-1)π z), k = 1..M              truncated Fourier step   with the defaults
//
// "Lower bound" means shadow <= Z(z < zf) for EVERY distribution Z with the stored moments, so
// these techniques can only leak light, never darken (2015 §3). "Sharp" means it is the infimum
// of Problem 1 (2015 §3), i.e. what the LP oracle computes; 2015 §3: "For I = R ... VSM and ESM
// both provide solutions to Problem 1", and VSM is Hamburger MSM with m = 2 (2015 §4.1).
//
// Bits per texel of each variant (channels x bits per channel):
//   VSM   32 bits: θ2(z, z²) in 2 x 16-bit UNORM (RG16_UNORM), [0,1] depth (2015 §4.3, Fig. 1)
//   VSM   64 bits: (z, z²) in 2 x 32-bit float (RG32_SFLOAT), any depth convention
//   ESM   32 bits: exp(c z) in 1 x 32-bit float (R32_SFLOAT), c = 80 for [0,1] depth
//   EVSM2 32 bits: 2 x 16-bit float (RG16_SFLOAT), c+ = 5.54, [-1,1] depth
//   EVSM2 64 bits: 2 x 32-bit float (RG32_SFLOAT), c+ = 40, [-1,1] depth
//   EVSM4 64 bits: 4 x 16-bit float (RGBA16_SFLOAT), c+ = c- = 5.54, [-1,1] depth (JCGT Fig. 4a)
//   EVSM4 128 bits: 4 x 32-bit float (RGBA32_SFLOAT), c+ = 40, c- = 5.54 (JCGT Fig. 4e)
//   CSM   2M channels in ceil(M/2) RGBA textures: 64 M bits in float, 32 M in 16 bits,
//         16 M in 8-bit UNORM (sin/cos mapped to [0,1], msm_csm_to_unorm); M <= 16.
// The exponent c of an exponential warp is set by the CHANNEL format, not by the texel size:
// it is the largest one for which the largest stored value (exp(2c) for the squared warp of
// EVSM, exp(c) for ESM) still fits the channel's range; see the EVSM section.
//
// All functions follow shared.h: valid GLSL 4.60 and C++20 (namespace msm, single precision).
#ifndef MSM_BASELINES_H
#define MSM_BASELINES_H
#include "msm/config.h"
#include "msm/quantize.h"
#include "msm/shared.h"

MSM_BEGIN

// ================================ Shading helpers ================================================

// Over-darkening (Annen et al. 2007; JCGT §2.6): shadow intensities are divided by 'factor' and
// clamped, so that light leaking below 1 - factor disappears: shadow >= factor gives 1, shadow = 0
// stays 0, and the map is linear in between. Default factor MSM_OVERDARKEN_DEFAULT = 0.98 (JCGT).
// Any factor < 1 darkens, so the result is no longer a lower bound of Z(z < zf).
MSM_FN float msm_overdarken(float shadow, float factor) { return msm_saturate(shadow / factor); }
MSM_FN float msm_overdarken(float shadow) { return msm_overdarken(shadow, MSM_OVERDARKEN_DEFAULT); }

// ================================ VSM (Donnelly & Lauritzen 2006) ================================
// Depth convention: any (the caller's), except for the θ2 storage which needs [0,1] depth.
// Reconstruction by Cantelli's (one-sided Chebyshev) inequality with μ = b1, σ² = b2 - b1²:
//   shadow = 0                          if zf <= μ,
//   shadow = 1 - σ²/(σ² + (zf - μ)²)     otherwise,
// the sharp lower bound of Z(z < zf) over all distributions on R with mean μ and variance σ²
// (Hamburger moment problem with m = 2, 2015 §4.1).
// The variance is clamped below at 'min_variance' (in squared depth units of the convention):
// rounding can make b2 - b1² negative or too small, which gives acne next to the occluder.
// A larger variance can only lower the Cantelli value, so the clamp keeps the lower bound.
// Defaults, from the worst-case rounding of σ² ([0,1] depth):
//  - 2 x 32-bit float: b1, b2 and b1² carry relative errors near 2^-24 = 6e-8, so the computed
//    σ² is off by about 2e-7 at most; with a 5x margin for the filter sums: 1e-6.
//  - θ2 in 2 x 16-bit UNORM: σ² = q1 - q1² - q2/4 with |∂σ²/∂q1| <= 1, |∂σ²/∂q2| = 1/4 and
//    rounding errors <= 0.5/65535 in each q: 9.5e-6 at most; with a 2x margin: 2e-5.
// A receiver at distance d behind a lone occluder gets d²/(v + d²): 99% needs d >= 10 sqrt(v).
const float MSM_VSM_MIN_VARIANCE_FLOAT = 1.0e-6f;
const float MSM_VSM_MIN_VARIANCE_UNORM16 = 2.0e-5f;

// Generation: b(z) = (z, z²).
MSM_FN vec2 msm_vsm_moments(float z) { return vec2(z, z * z); }

// Reconstruction from b = E(z, z²).
MSM_FN float msm_vsm_shadow(vec2 b, float zf, float min_variance) {
  float mean = b[0];
  if (!(zf > mean)) return 0.0f; // NaN reads lit, as in every moment technique
  float variance = b[1] - mean * mean;
  variance = variance > min_variance ? variance : min_variance; // a select: no NaN reaches max()
  float d = zf - mean;
  // d²/(σ² + d²) = 1 - σ²/(σ² + d²), without the cancellation for small shadows.
  return msm_saturate((d * d) / (variance + d * d));
}
MSM_FN float msm_vsm_shadow(vec2 b, float zf) { return msm_vsm_shadow(b, zf, MSM_VSM_MIN_VARIANCE_FLOAT); }

// 32-bit VSM ([0,1] depth): the texel stores θ2(z, z²) = (z, 4z - 4z²), which fills [0,1]²
// (2015 §4.3, +2 bits of entropy); the renderer writes it to RG16_UNORM.
MSM_FN vec2 msm_vsm_moments_theta2(float z) { return msm_theta2(msm_vsm_moments(z)); }
MSM_FN float msm_vsm_shadow_theta2(vec2 q, float zf, float min_variance) {
  return msm_vsm_shadow(msm_theta2_inverse(q), zf, min_variance);
}
MSM_FN float msm_vsm_shadow_theta2(vec2 q, float zf) {
  return msm_vsm_shadow_theta2(q, zf, MSM_VSM_MIN_VARIANCE_UNORM16);
}

// Light-bleeding reduction (Lauritzen, GPU Gems 3 ch. 8): the lit fraction 1 - shadow is
// remapped by linstep(amount, 1, .), so that lit fractions below 'amount' become fully shadowed.
// amount in [0, 1): 0 = off (the default), 0.2-0.3 is typical. Algebraically this equals
// msm_overdarken(shadow, 1 - amount), which computes it; it is no longer a lower bound.
MSM_FN float msm_vsm_reduce_light_bleeding(float shadow, float amount) { return msm_overdarken(shadow, 1.0f - amount); }

// ================================ ESM (Salvi 2008; Annen et al. 2008) ============================
// Generation: b(z) = exp(c z). Reconstruction by Markov's inequality applied to the positive
// variable exp(c z): Z(z >= zf) <= E exp(c z) / exp(c zf), so
//   shadow = saturate(1 - b exp(-c zf))
// is a lower bound of Z(z < zf) for ANY distribution on R and ANY zf (no support condition), and
// it is the sharp one for I = R (mass at zf and at -infinity attains it in the limit). On a
// bounded interval [lo, hi] the sharp bound is 1 - (b - exp(c lo)) / (exp(c zf) - exp(c lo)),
// which is larger: ESM does not use the knowledge that depths are bounded below.
// Depth convention and numerical range: only c times the width of the depth range matters, since
// exp(c z) with z' = 2z - 1 is exp(c/2 z') times a constant that cancels in b exp(-c zf).
//  - [0,1] depth, 32-bit float: stored values lie in [1, exp(c)], and FLT_MAX = exp(88.72), so
//    c < 88.7; c = 80 (MSM_ESM_C_DEFAULT) leaves a factor exp(8.7) = 6000 of headroom for
//    filters that sum weighted taps before normalizing (summed-area tables overflow regardless).
//  - [-1,1] depth: c = 40 gives the same shadows as c = 80 on [0,1]; floats hold values in
//    [exp(-c), exp(c)] as normal numbers (>= FLT_MIN = exp(-87.3)) up to c = 87, i.e. signed
//    depth allows twice the sharpness of unit depth in the same channel.
//  - 16-bit float channels (max 65504 = exp(11.09)): c <= 11.09 on [0,1] ([-1,1]: also 11.09,
//    which is worth 22 on [0,1]).
// Larger c sharpens the shadow (less leaking behind occluders) but strengthens the failure of
// ESM where the receiver is not behind all occluders: each occluder behind the receiver
// subtracts its weight times exp(c (z - zf)) >> 1 from the shadow (too light at receiver
// boundaries, 2015 §2).
MSM_FN float msm_esm_moment(float z, float c) { return exp(c * z); }
MSM_FN float msm_esm_shadow(float b, float zf, float c) { return msm_saturate(1.0f - b * exp(-c * zf)); }
MSM_FN float msm_esm_shadow(float b, float zf) { return msm_esm_shadow(b, zf, MSM_ESM_C_DEFAULT); }

// Log-space filtering (Salvi 2008): the texel stores L = c z (R32_SFLOAT; never overflows, so c
// is not limited by the float range; half would be too coarse, ulp 0.06 at L = 80), filters
// combine log-moments with log-sum-exp, and reconstruction reads log(b) = L directly. Same
// shadows as the linear variant (tested to 1e-5 at c = 80).
MSM_FN float msm_esm_log_moment(float z, float c) { return c * z; }
// log((1 - t) exp(la) + t exp(lb)), t in [0,1]: the blend of two log-moments (a filter tap).
// Shifting by the larger argument keeps exp() <= 1; with |la - lb| <= 87 nothing underflows to 0.
MSM_FN float msm_esm_log_mix(float la, float lb, float t) {
  float m = max(la, lb);
  return m + log((1.0f - t) * exp(la - m) + t * exp(lb - m));
}
MSM_FN float msm_esm_shadow_log(float log_b, float zf, float c) { return msm_saturate(1.0f - exp(log_b - c * zf)); }

// ================================ EVSM (Lauritzen & McCool 2008) ================================
// Depth convention: [-1,1] (JCGT Fig. 4); z and zf are clamped to it, which bounds the warped
// values. Both warps are strictly increasing in z,
//   w+(z) = exp(c+ z),   w-(z) = -exp(-c- z),
// so z < zf <=> w(z) < w(zf), and VSM on either warped depth is a lower bound of Z(z < zf); so
// is the larger ("darker", 2015 §2) of the two, which EVSM4 returns. It is not sharp for the
// stored moments (2015 §3).
// EVSM2 stores (w+, w+²); EVSM4 stores (w+, w+², w-, w-²) (JCGT §2.2 order, b0 = 1 implicit).
// Exponents per channel format (config.h), limited by the squared warp exp(2c) at |z| = 1:
//  - 16-bit float: max 65504 = exp(11.090), so 2c <= 11.09, c <= 5.545: c = 5.54
//    (MSM_EVSM_C_64BIT): exp(2 * 5.54) = 64,853 fits, exp(2 * 5.55) = 66,171 overflows to inf.
//    exp(5.54) = 254.7 itself fits easily (ulp 0.125, relative precision 2^-11 = 4.9e-4);
//    the small end exp(-2c) = 1.5e-5 is a half subnormal (min normal 6.1e-5), which only
//    affects texels whose contribution is negligible at the receiver anyway.
//    The cost is precision: σ² = E w² - (E w)² cancels, and the half rounding of w² and w
//    leaves an error near 1.5e-3 w²; through the warp slope dw/dz = c w that is a depth variance
//    of 1.5e-3 / c² = 4.8e-5 (standard deviation 0.007 in [-1,1] units): the quantization noise
//    and leaking of JCGT Fig. 4a.
//  - 32-bit float: max exp(88.72), so c <= 44.36: c+ = 40 (exp(80) = 5.5e34) and c- = 5.54
//    (JCGT Fig. 4e: MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT).
// Minimum variance: given in DEPTH units ([-1,1] depth) and mapped to each warp through its
// slope at the receiver, min_variance * (c w(zf))², the first-order variance of w for a depth
// variance 'min_variance' around zf (the scaling used in common EVSM implementations). Defaults
// from the worst-case rounding of σ²:
//  - 16-bit float channels: 4.8e-5 (above), with a 2x margin: 1e-4;
//  - 32-bit float channels: relative errors ~2e-7 of w² after storage, i.e. a depth variance of
//    2e-7/c² <= 6e-9 (c- = 5.54 is the critical warp), with a 5x margin for the rounding of the
//    filter sums on top: 1e-7.
// Measured self-shadowing of a flat surface (zf = its depth, the acne case): 7.7e-5 with 1e-4
// after half storage (8e-3 with 1e-6, 1 with 0); 1.2e-7 with 1e-7 after float storage and a
// float 9x9 Gaussian (1 with 0).
const float MSM_EVSM_MIN_VARIANCE_HALF = 1.0e-4f;
const float MSM_EVSM_MIN_VARIANCE_FLOAT = 1.0e-7f;

// (w+(z), w-(z)) for depth z in [-1,1] (clamped).
MSM_FN vec2 msm_evsm_warp(float z, float c_pos, float c_neg) {
  float zc = clamp(z, -1.0f, 1.0f);
  return vec2(exp(c_pos * zc), -exp(-c_neg * zc));
}

// Generation.
MSM_FN vec2 msm_evsm2_moments(float z, float c_pos) {
  float w = exp(c_pos * clamp(z, -1.0f, 1.0f));
  return vec2(w, w * w);
}
MSM_FN vec4 msm_evsm4_moments(float z, float c_pos, float c_neg) {
  vec2 w = msm_evsm_warp(z, c_pos, c_neg);
  return vec4(w[0], w[0] * w[0], w[1], w[1] * w[1]);
}

// VSM on one warp: b = E(w, w²), wf = w(zf), slope = dw/dz at zf; min_variance in depth units.
// (min_variance * slope) * slope rather than slope² keeps the product finite up to c = 44.
MSM_FN float msm_evsm_warped_shadow(vec2 b, float wf, float slope, float min_variance) {
  return msm_vsm_shadow(b, wf, (min_variance * slope) * slope);
}

// Reconstruction.
MSM_FN float msm_evsm2_shadow(vec2 b, float zf, float c_pos, float min_variance) {
  float wf = exp(c_pos * clamp(zf, -1.0f, 1.0f));
  return msm_evsm_warped_shadow(b, wf, c_pos * wf, min_variance);
}
MSM_FN float msm_evsm4_shadow(vec4 b, float zf, float c_pos, float c_neg, float min_variance) {
  vec2 wf = msm_evsm_warp(zf, c_pos, c_neg);
  float pos = msm_evsm_warped_shadow(vec2(b[0], b[1]), wf[0], c_pos * wf[0], min_variance);
  // dw-/dz = c- exp(-c- z) = -c- w-; only its square enters.
  float neg = msm_evsm_warped_shadow(vec2(b[2], b[3]), wf[1], c_neg * wf[1], min_variance);
  return max(pos, neg);
}

// Round-trips through 16-bit float storage (RG16_SFLOAT / RGBA16_SFLOAT).
MSM_FN vec2 msm_quantize_half2(vec2 v) { return unpackHalf2x16(packHalf2x16(v)); }
MSM_FN vec4 msm_quantize_half4(vec4 v) {
  vec2 a = msm_quantize_half2(vec2(v[0], v[1]));
  vec2 b = msm_quantize_half2(vec2(v[2], v[3]));
  return vec4(a[0], a[1], b[0], b[1]);
}

// ================================ CSM (Annen et al. 2007) =======================================
// Convolution shadow maps (not cascaded shadow maps). Depth convention: [0,1], for occluders and
// receivers alike. The shadow test is the step H(zf - z) (1 when the occluder is in front);
// on x = zf - z in [-1,1] it is the square wave of period 2 whose Fourier series is
//   H(x) = 1/2 + 2 sum_{k>=1} sin(c_k x) / c_k,   c_k = (2k - 1) π,
// and sin(c_k (zf - z)) = sin(c_k zf) cos(c_k z) - cos(c_k zf) sin(c_k z) separates, so the
// texel stores the 2M basis values (sin c_k z, cos c_k z), k = 1..M, and after filtering
//   S_M(zf) = 1/2 + 2 sum_{k<=M} σ_k / c_k (sin(c_k zf) E cos(c_k z) - cos(c_k zf) E sin(c_k z))
// estimates Z(z < zf). Without damping (σ_k = 1) S_M converges to the filtered step as M grows,
// away from the discontinuities (x = 0: receiver at an occluder depth; and x = ±1, the jump of
// the periodic extension: occluder at 0 and receiver at 1); next to them it rings (Gibbs: the
// truncated series overshoots 1 and undershoots 0 by 9% of the jump for every M) and it is 1/2
// at x = 0, i.e. half-shadowed surfaces (acne).
// The original paper's remedies, here as CsmParams (the exact form of each is our reading of
// Annen et al. 2007 and of implementations of it; the paper text is not in shared/papers):
//  - damping: ringing suppression, σ_k = exp(-damping (k/M)²) attenuates the high frequencies
//    (smoother step, less ringing, more blur);
//  - offset: the receiver depth is shifted towards the light, zf - offset (then clamped to >= 0
//    so that x stays in [-1,1], where the series is the step);
//  - scale: the "scaled expansion": the lit fraction 1 - S is multiplied by 'scale' and clamped,
//    shadow = saturate(1 - scale (1 - S)); with scale = 2 the half-shadow at x = 0 becomes 0.
// These bias the reconstruction toward a LOWER BOUND: S_M(-x) = 1 - S_M(x), and S_M >= 1/2 on
// [0,1] (for the plain series the classical positivity of sum sin((2k-1)t)/(2k-1) on (0,π);
// for damping 0..4 and M <= 16 checked numerically), so S_M <= 1/2 on [-1,0]. Then any
// scale >= 2 gives saturate(1 - scale (1 - S_M(x))) <= H(x) wherever S_M <= 1, and this
// pointwise bound survives the expectation over Z; an offset >= 0 only lowers it further. With
// the default damping 2, S_M <= 0.999 for every M <= 16 (no overshoot), so the defaults
// (damping 2, scale 2, offset 0) give shadow <= Z(z < zf) for every distribution on [0,1]
// (tested). Without damping the Gibbs overshoot breaks the bound near x = 0+. The price is
// light leaking: a receiver a distance x behind a lone occluder gets 2 S_M(x) - 1, which reaches
// 0.9 only at x = 0.25 for M = 4 and x = 0.035 for M = 16.
// Interface: M <= MSM_CSM_MAX_TERMS = 16 is a parameter (GLSL has no dynamic arrays): RGBA
// texel t (0-based) holds the terms k = 2t+1 and 2t+2 as (sin, cos, sin, cos); the renderer
// keeps ceil(M/2) such textures (or layers), and the shader sums msm_csm_texel_terms() over
// them, or gathers them into a CsmMoments (8 texels = 16 terms) and calls msm_csm_shadow().
const int MSM_CSM_MAX_TERMS = 16;
const int MSM_CSM_MAX_TEXELS = 8;
const int MSM_CSM_TERMS_DEFAULT = 16;
const float MSM_CSM_DAMPING_DEFAULT = 2.0f;
const float MSM_CSM_SCALE_DEFAULT = 2.0f;
const float MSM_CSM_OFFSET_DEFAULT = 0.0f;

struct CsmParams {
  int terms;     // M, 1..16
  float damping; // α of σ_k = exp(-α (k/M)²); 0 = plain truncated series
  float scale;   // shadow = saturate(1 - scale (1 - S)); 1 = none
  float offset;  // receiver shift towards the light, in [0,1] depth units; 0 = none
};

MSM_FN CsmParams msm_csm_default_params() {
  return CsmParams(MSM_CSM_TERMS_DEFAULT, MSM_CSM_DAMPING_DEFAULT, MSM_CSM_SCALE_DEFAULT, MSM_CSM_OFFSET_DEFAULT);
}
// The plain truncated Fourier series (no damping, scale or offset).
MSM_FN CsmParams msm_csm_plain_params(int terms) { return CsmParams(terms, 0.0f, 1.0f, 0.0f); }

// c_k = (2k - 1) π, k >= 1.
MSM_FN float msm_csm_frequency(int k) { return float(2 * k - 1) * MSM_PI; }

// Generation: term k (1-based), (sin c_k z, cos c_k z).
MSM_FN vec2 msm_csm_basis(float z, int k) {
  float a = msm_csm_frequency(k) * z;
  return vec2(sin(a), cos(a));
}
// RGBA texel t (0-based): terms 2t+1 and 2t+2.
MSM_FN vec4 msm_csm_basis_texel(float z, int t) {
  return vec4(msm_csm_basis(z, 2 * t + 1), msm_csm_basis(z, 2 * t + 2));
}
// 8-bit (or 16-bit) UNORM storage of basis values in [-1,1].
MSM_FN vec4 msm_csm_to_unorm(vec4 v) { return 0.5f * v + vec4(0.5f); }
MSM_FN vec4 msm_csm_from_unorm(vec4 u) { return 2.0f * u - vec4(1.0f); }

// The receiver depth the series is evaluated at.
MSM_FN float msm_csm_receiver(float zf, CsmParams p) { return max(zf - p.offset, 0.0f); }

// The depth range the basis tiles, for the shadow map techniques: the hard CSM technique (csm-4,
// src/core/techniques.cpp) and CSSM (cssm.h) store the basis at u = MSM_CSM_BASIS_RANGE z and
// evaluate the series at the receiver's u (msm_csm_ranged_receiver). Why: the series in the depth
// difference t = x - z is a square wave of period 2 (c_k = (2k - 1) π), 1 on (0, 1), 0 on (-1, 0),
// and, damped, it falls back through 1/2 at t = 1 as it rises through 1/2 at t = 0 (S(1 - t) =
// S(t)). On the unscaled basis a receiver on the fitted map's far plane (depth 1) behind a blocker
// on its near plane (0) gets S = 1/2, shadow 0 after the scale 2: no shadow at all where the lowest
// receivers of a scene lie under its highest blockers. Scaled by 3/4 the differences stay within
// [-3/4, 3/4], and the far end t = 3/4 is as far from the next jump as t = 1/4 from the first (the
// best worst case over differences in [1/3, 1], R = 1 / (1 + 1/3)). The price: the ramp near
// contact is 4/3 as wide in depth (more light leaking where receivers are near their blockers).
// msm_csm_moments / msm_csm_shadow and the scattering CSM (scattering.h, rectification.h: a
// rectified map with a guard band) keep the unscaled basis.
const float MSM_CSM_BASIS_RANGE = 0.75f;
// The depth the basis sees for a depth z in [0,1].
MSM_FN float msm_csm_basis_depth(float z) { return MSM_CSM_BASIS_RANGE * z; }
// The receiver depth the series is evaluated at, on the basis's scale, for a receiver at zf in [0,1].
MSM_FN float msm_csm_ranged_receiver(float zf, CsmParams p) { return msm_csm_basis_depth(msm_csm_receiver(zf, p)); }

// Contribution of term k to S_M, from the filtered (E sin c_k z, E cos c_k z) and the receiver
// depth xf = msm_csm_receiver(zf, p); 0 for k > p.terms.
MSM_FN float msm_csm_term(vec2 sin_cos, float xf, int k, CsmParams p) {
  if (k > p.terms) return 0.0f;
  float r = float(k) / float(p.terms);
  float ck = msm_csm_frequency(k);
  float a = ck * xf;
  return 2.0f * exp(-p.damping * r * r) / ck * (sin(a) * sin_cos[1] - cos(a) * sin_cos[0]);
}
// Contribution of the two terms in filtered RGBA texel t.
MSM_FN float msm_csm_texel_terms(vec4 texel, float xf, int t, CsmParams p) {
  return msm_csm_term(vec2(texel[0], texel[1]), xf, 2 * t + 1, p) +
         msm_csm_term(vec2(texel[2], texel[3]), xf, 2 * t + 2, p);
}
// From the sum of all term contributions to the shadow intensity: S = 1/2 + sum, then scale.
MSM_FN float msm_csm_resolve(float term_sum, CsmParams p) { return msm_saturate(1.0f - p.scale * (0.5f - term_sum)); }

// All 16 terms of one texel: columns 0..3 of lo are texels 0..3, columns of hi texels 4..7.
struct CsmMoments {
  mat4 lo;
  mat4 hi;
};

MSM_FN vec4 msm_csm_texel(CsmMoments m, int t) { return t < 4 ? m.lo[t] : m.hi[t - 4]; }

// Generation of the first 'terms' terms (the rest stay 0).
MSM_FN CsmMoments msm_csm_moments(float z, int terms) {
  CsmMoments m = CsmMoments(mat4(0.0f), mat4(0.0f));
  for (int t = 0; t < MSM_CSM_MAX_TEXELS; ++t) {
    if (2 * t + 1 > terms) break;
    vec4 v = msm_csm_basis_texel(z, t);
    if (2 * t + 2 > terms) v = vec4(v[0], v[1], 0.0f, 0.0f);
    if (t < 4)
      m.lo[t] = v;
    else
      m.hi[t - 4] = v;
  }
  return m;
}
// acc + w m (filtering, resolves, blending).
MSM_FN CsmMoments msm_csm_moments_scale_add(CsmMoments acc, CsmMoments m, float w) {
  return CsmMoments(acc.lo + w * m.lo, acc.hi + w * m.hi);
}

// S_M at receiver depth xf, unclamped (the raw series with p's damping; offset and scale are
// not applied): what the convergence and ringing tests look at.
MSM_FN float msm_csm_series(CsmMoments m, float xf, CsmParams p) {
  float sum = 0.0f;
  for (int t = 0; t < MSM_CSM_MAX_TEXELS; ++t) {
    if (2 * t + 1 > p.terms) break;
    sum += msm_csm_texel_terms(msm_csm_texel(m, t), xf, t, p);
  }
  return 0.5f + sum;
}

// Reconstruction: the shadow intensity for fragment depth zf in [0,1].
MSM_FN float msm_csm_shadow(CsmMoments m, float zf, CsmParams p) {
  float series = msm_csm_series(m, msm_csm_receiver(zf, p), p);
  return msm_csm_resolve(series - 0.5f, p);
}

MSM_END

#endif // MSM_BASELINES_H
