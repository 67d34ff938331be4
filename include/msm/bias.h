// Moment biasing b' = (1 - α) b + α b*: pulls moments corrupted by rounding back inside the
// domain where the Hankel matrix is positive definite (2015 §4.2, JCGT §2.5). The pair (α, b*)
// depends on how the moments were stored; msm_moment_bias() picks it by representation.
#ifndef MSM_BIAS_H
#define MSM_BIAS_H
#include "msm/config.h"
#include "msm/hamburger4.h"
#include "msm/moments.h"
#include "msm/shared.h"

MSM_BEGIN

// Storage representations of four moments (GLSL has no enums).
const int MSM_REP_UNIT_FLOAT = 0;    // [0,1] depth, 4 x 32-bit float (2015, JCGT Fig. 4d)
const int MSM_REP_UNIT_THETA4 = 1;   // [0,1] depth, 4 x 16-bit UNORM after θ4 (2015)
const int MSM_REP_SIGNED_FLOAT = 2;  // [-1,1] depth, 4 x 32-bit float (JCGT §2.3)
const int MSM_REP_SIGNED_THETA4 = 3; // [-1,1] depth, 4 x 16-bit UNORM after Θ4* (JCGT §2.4)
const int MSM_REP_SAT_INT32 = 4;     // [-1,1] depth, Θ4*, 32-bit integer summed-area table
// Six moments ([-1,1] depth, Θ6*).
const int MSM_REP6_UNORM10 = 10; // 6 x 10-bit in two RGB10A2 textures (64 bits)
const int MSM_REP6_UNORM16 = 11; // 6 x 16-bit (96 bits)
const int MSM_REP6_FLOAT = 12;   // 6 x 32-bit float (192 bits)

struct MomentBias4 {
  float alpha;
  vec4 bstar; // (b1..b4) of the biasing distribution
};

struct MomentBias6 {
  float alpha;
  Moments6 bstar;
};

MSM_FN MomentBias4 msm_moment_bias(int representation) {
  if (representation == MSM_REP_UNIT_FLOAT) return MomentBias4(MSM_ALPHA_UNIT_FLOAT, MSM_BSTAR_UNIT);
  if (representation == MSM_REP_UNIT_THETA4) return MomentBias4(MSM_ALPHA_UNIT_16BIT, MSM_BSTAR_UNIT);
  if (representation == MSM_REP_SIGNED_FLOAT) return MomentBias4(MSM_ALPHA_SIGNED_FLOAT, MSM_BSTAR_SIGNED_FLOAT);
  if (representation == MSM_REP_SIGNED_THETA4) return MomentBias4(MSM_ALPHA_SIGNED_16BIT, MSM_BSTAR_SIGNED_16BIT);
  // Summed-area tables store Θ4* moments at ~22.5 bits. Their rounding happens after Θ4*, as for
  // 16-bit Θ4* storage, so b* is the one measured after Θ4* (JCGT §2.5; App. D.4 and the authors'
  // Convert4MomentOptimizedToCanonical use 0.628 with α = 6e-7). With the float b* (0.375), 509 of
  // 40000 biased one-texel queries of single depths were not positive definite, 147 with 0.628
  // (edges_test, SatBiasTargetIsMeasuredAfterTheTransform); α = 6e-7 stays the paper's, the rest
  // is what hamburger4.h's D2 floor is for.
  return MomentBias4(MSM_ALPHA_SAT_INT32, MSM_BSTAR_SIGNED_16BIT);
}

MSM_FN MomentBias6 msm_moment_bias6(int representation) {
  Moments6 bstar = Moments6(vec3(0.0f), MSM_BSTAR6_EVEN);
  if (representation == MSM_REP6_UNORM10) return MomentBias6(MSM_ALPHA6_10BIT, bstar);
  if (representation == MSM_REP6_UNORM16) return MomentBias6(MSM_ALPHA6_16BIT, bstar);
  return MomentBias6(MSM_ALPHA6_FLOAT, bstar);
}

// Receiver-plane depth bias of filtered shadow maps (subtracted from the fragment depth zf).
// On a planar receiver whose depth changes by g per texel, the filter kernel around a fragment
// holds the receiver's own depths zf + g·o, o distributed like the kernel (Gaussian taps, the
// lookup's bilinear/trilinear footprint and the MSAA sample positions: independent per axis, each
// symmetric about 0 with variance v texels²). That distribution is symmetric about zf with
// standard deviation σ = |g| √v; half of it lies in front of zf, and how much of that half a
// technique reports as shadow depends on its bound, so the bias is σ times a factor per bound:
// - four moments (Hamburger or Hausdorff 4MSM): the lower bound of Z(z < zb) is 0 iff a
//   distribution on [zb, ∞) has the moments, iff the localizing matrix
//   [[b1 − zb b0, b2 − zb b1], [b2 − zb b1, b3 − zb b2]] is positive semidefinite; for moments
//   centred on zf with b1 = b3 = 0, b2 = σ² (any symmetric distribution) that is (zf − zb)² ≥ σ²:
//   a bias of exactly σ, whatever the shape of the kernel. Without it a Gaussian kernel on a slope
//   reads a shadow of 1/6 (atoms at zf ± √3σ of weight 1/6); the moment bias then adds at most α;
// - six moments: the 3x3 localizing matrix; it needs √3 σ for Gaussian depths (the limit of sums
//   of independent offsets), 1.52-1.64 σ for the renderer's 9-tap σ = 2.4 kernel at any slope
//   direction (computed), so √3 is the bias that holds for any such kernel;
// - two moments (Cantelli, VSM), ESM (Markov on e^{cz}, Jensen) and the positive warp of EVSM:
//   no shadow at the mean depth, so no bias;
// - the negative warp −e^{−c z} of EVSM4: Cantelli reports shadow unless the warped zb is below
//   the warped mean, i.e. e^{−c zb} ≥ E[e^{−c z}] = e^{−c zf + c²σ²/2} for Gaussian depths:
//   zf − zb ≥ c σ²/2 (depths and σ in the warp's [-1,1] units).
const float MSM_RECEIVER_SIGMAS4 = 1.0f;       // four moments: exact, for any symmetric kernel
const float MSM_RECEIVER_SIGMAS6 = 1.7320508f; // six moments: √3, the Gaussian limit

// σ of the receiver's depth over the kernel: depth_per_texel = (dz/dx, dz/dy) per texel,
// kernel_variance = the kernel's variance per axis in texels² (the same along x and y).
MSM_FN float msm_receiver_depth_sigma(vec2 depth_per_texel, float kernel_variance) {
  return sqrt(max(kernel_variance, 0.0f)) * length(depth_per_texel);
}
// The bias a negative exponential warp −e^{−c z} needs (see above), for σ in [-1,1] depth.
MSM_FN float msm_receiver_plane_bias_negative_warp(float sigma, float c) { return 0.5f * c * sigma * sigma; }

// mix(b, b*, α) written out as GLM computes it, b (1 - α) + b* α, and `precise`: GLSL's mix() may
// round otherwise (WebGL 2 on SwiftShader differs from GLM in the last bit for 61% of moment
// vectors), and one ulp of the float-biased moments of a single depth (α = 3e-7) moved Hamburger
// 4MSM by up to 0.15 for receivers just behind it (web/test/math.test.mjs).
MSM_FN vec4 msm_apply_bias(vec4 b, float alpha, vec4 bstar) {
  MSM_PRECISE vec4 biased = b * (1.0f - alpha) + bstar * alpha;
  return biased;
}

// b with b4 raised so that the last LDLᵀ pivot D2 = b4 - b2² - L21² D1 (hamburger4.h) is at least
// min_d2: adding to b4 adds the same to D2 and leaves b0..b3 alone, and a larger D2 only lowers
// the lower bound (HPG §3.2), so this is the light side of a vector whose D2 the storage rounded
// away. For the 2015 θ4 16-bit representation (MSM_MIN_D2_UNIT_16BIT, config.h); every other
// representation relies on its bias and on hamburger4.h's float floor.
MSM_FN vec4 msm_raise_d2(vec4 b, float min_d2) {
  return vec4(b[0], b[1], b[2], b[3] + msm_at_least(min_d2 - msm_hankel3_ldl(b).D2, 0.0f));
}
MSM_FN vec4 msm_apply_bias(vec4 b, MomentBias4 bias) { return msm_apply_bias(b, bias.alpha, bias.bstar); }
MSM_FN Moments6 msm_apply_bias6(Moments6 b, MomentBias6 bias) { return msm_moments6_mix(b, bias.bstar, bias.alpha); }

MSM_END

#endif // MSM_BIAS_H
