// Cascaded shadow maps: how much of a directional light's shading one cascade (one layer of the
// shadow-map arrays) takes at a view depth, the one formula the shading (shading.glsl) and the
// tests share. Adjacent cascades' weights sum to 1: over the band at a cascade's far end it fades
// out as the next fades in, so their shadows blend instead of meeting at a seam.
#ifndef MSM_CASCADE_H
#define MSM_CASCADE_H
#include "msm/filter.h"
#include "msm/shared.h"

MSM_BEGIN

// 0 below `from`, 1 above `to`, the cubic smoothstep between; a step at `to` where the band is empty.
MSM_FN float msm_cascade_ramp(float from, float to, float x) {
  if (!(to > from)) return x >= to ? 1.0f : 0.0f;
  float t = clamp((x - from) / (to - from), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// The weight of a cascade at view depth `depth` (the camera's, > 0): `cascade` holds the view depths
// where it rises from 0 (x) to 1 (y) and where it falls from 1 (z) to 0 (w), frame.h's
// LightUniforms::cascade. w <= 0: a light without cascades, weight 1.
MSM_FN float msm_cascade_weight(vec4 cascade, float depth) {
  if (cascade.w <= 0.0f) return 1.0f;
  return msm_cascade_ramp(cascade.x, cascade.y, depth) * (1.0f - msm_cascade_ramp(cascade.z, cascade.w, depth));
}

// The filter in world units. A cascade's texels are larger than the first cascade's by 1 / scale
// (scale = the first cascade's texel size over its own, in (0, 1]); the frame's Gaussian (`taps`,
// σ in the first cascade's texels, msm/filter.h) becomes, in the cascade's own texels, the one of
// radius round(r scale) whose whole filter has the first's variance in world units: the Gaussian's
// (msm_gaussian_variance) plus what the chain adds in each layer's own texels and no scale changes
// (`added`: the bilinear lookup's tent, 1/6 texel², and the MSAA positions'), so that
//     var(taps_i, σ_i) + added = (var(taps, σ) + added) scale².
// The blur, the PCF kernel and the receiver-plane bias then span the same width in world units in
// every cascade, and a penumbra keeps its size across their borders.
// Clamped where that is narrower than a filter can be: at least 3 taps (radius 1) and σ at least
// MSM_CASCADE_MIN_SIGMA texels (3 taps of a narrower σ weigh their side taps under 0.11: nearly a
// copy of the texel), or the frame's own where it is narrower still; never wider than the frame's
// (a scale above 1 counts as 1).
const float MSM_CASCADE_MIN_SIGMA = 0.5f;

MSM_FN int msm_cascade_filter_taps(int taps, float scale) {
  int radius = taps / 2;
  if (radius == 0) return taps;
  int scaled = int(floor(float(radius) * min(scale, 1.0f) + 0.5f));
  return 2 * (scaled > 1 ? scaled : 1) + 1;
}

// σ of the cascade's msm_cascade_filter_taps(taps, scale) taps (bisection on the variance, which
// grows with σ).
MSM_FN float msm_cascade_filter_sigma(int taps, float sigma, float scale, float added) {
  int scaled_taps = msm_cascade_filter_taps(taps, scale);
  float s = min(scale, 1.0f);
  float target = (msm_gaussian_variance(taps, sigma) + added) * s * s - added;
  float lo = min(sigma, MSM_CASCADE_MIN_SIGMA), hi = sigma;
  if (msm_gaussian_variance(scaled_taps, lo) >= target) return lo;
  if (msm_gaussian_variance(scaled_taps, hi) <= target) return hi;
  for (int i = 0; i < 40; ++i) {
    float mid = 0.5f * (lo + hi);
    if (msm_gaussian_variance(scaled_taps, mid) < target)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5f * (lo + hi);
}

MSM_END

#endif
