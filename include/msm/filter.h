// The Gaussian filter kernel of the filtered shadow maps, defined once for every user: the blur
// and PCF of the renderer, the ray tracer's filtered ground truth (msm/reference/kernel.h), the
// CLI defaults and the tests. A kernel of `taps` x `taps` texels (taps odd, radius r = taps / 2)
// with the separable weights w_k w_l of the normalized 1D Gaussian
//     w_k = exp(-(k - r)² / (2σ²)) / Σ_j exp(-(j - r)² / (2σ²)),   k = 0 .. taps - 1,
// then sampled bilinearly by the shading (a tent per axis).
// Defaults: the 2015 paper's 9 x 9 taps with σ = 2.4 texels (its §3.2 / Fig. 3 kernel; the
// renderer's blur and PCF and the ray tracer's filtered effect all use it unless told otherwise).
#ifndef MSM_FILTER_H
#define MSM_FILTER_H
#include "msm/shared.h"

MSM_BEGIN

const int MSM_FILTER_DEFAULT_TAPS = 9;
const float MSM_FILTER_DEFAULT_SIGMA = 2.4f;
// The largest kernel: 63 taps fill the 16 vec4s of FrameUniforms::filter_weights (render/frame.h);
// the ray tracer takes the same limit so that every kernel it accepts can be rendered.
const int MSM_FILTER_MAX_TAPS = 63;
// Bounds of σ in texels (a smaller σ makes one tap; a larger one a box).
const float MSM_FILTER_MIN_SIGMA = 1.0e-3f;
const float MSM_FILTER_MAX_SIGMA = 1.0e3f;

MSM_FN bool msm_filter_valid(int taps, float sigma) {
  return taps >= 1 && taps <= MSM_FILTER_MAX_TAPS && taps % 2 == 1 && sigma >= MSM_FILTER_MIN_SIGMA &&
         sigma <= MSM_FILTER_MAX_SIGMA;
}

// Unnormalized weight of the tap at `offset` texels from the centre.
MSM_FN float msm_gaussian_tap(float offset, float sigma) { return exp(-offset * offset / (2.0f * sigma * sigma)); }

// The normalized weight w_k of tap k in [0, taps). The sum runs outwards from the centre, in the
// same order for every k, so that the weights of one kernel add up to 1 within a few ulps.
MSM_FN float msm_gaussian_weight(int k, int taps, float sigma) {
  int r = taps / 2;
  float sum = 1.0f;
  for (int j = 1; j <= r; ++j) sum += 2.0f * msm_gaussian_tap(float(j), sigma);
  return msm_gaussian_tap(float(k - r), sigma) / sum;
}

// Variance per axis of the normalized taps, in texels²: Σ_k w_k (k - r)².
MSM_FN float msm_gaussian_variance(int taps, float sigma) {
  int r = taps / 2;
  float variance = 0.0f;
  for (int k = 0; k < taps; ++k) variance += msm_gaussian_weight(k, taps, sigma) * float((k - r) * (k - r));
  return variance;
}

// The same kernel in bilinear fetches (the blur): the centre tap alone, then on each side the
// taps 2j - 1 and 2j (j = 1 .. msm_filter_pairs) as one linear fetch between the two texels,
// with their summed weight at their weighted mean offset. A clamp-to-edge linear fetch returns
// exactly what the two clamped point fetches, so weighted, add up to: ceil(r/2) fetches per side
// instead of r, the same Gaussian. (The fraction is exact in float on lavapipe; GPUs that keep
// 8 bits of it move a pair's split by up to 1/512.) Where r is odd the outermost pair has one tap.
MSM_FN int msm_filter_pairs(int taps) { return (taps / 2 + 1) / 2; }

// Normalized weight of the tap `offset` texels from the centre, 0 outside the kernel.
MSM_FN float msm_filter_weight_at(int offset, int taps, float sigma) {
  int r = taps / 2;
  return abs(offset) <= r ? msm_gaussian_weight(offset + r, taps, sigma) : 0.0f;
}

// Summed weight of pair j in [1, msm_filter_pairs(taps)] (on one side).
MSM_FN float msm_filter_pair_weight(int j, int taps, float sigma) {
  return msm_filter_weight_at(2 * j - 1, taps, sigma) + msm_filter_weight_at(2 * j, taps, sigma);
}

// Offset in texels (> 0) of pair j's fetch; the other side's pair is at minus this. (A pair whose
// weights underflow, for a tiny σ, sits on its inner texel.)
MSM_FN float msm_filter_pair_offset(int j, int taps, float sigma) {
  float w = msm_filter_pair_weight(j, taps, sigma);
  return float(2 * j - 1) + (w > 0.0f ? msm_filter_weight_at(2 * j, taps, sigma) / w : 0.0f);
}

MSM_END

#endif // MSM_FILTER_H
