// Single scattering by ray marching (the baseline of JCGT 2017 §5.5.1): the sample distances and
// weights are scattering.h's (msm_ray_march_distance, msm_ray_march_weight: equidistant samples
// shifted by one jitter per pixel, each weighted by its segment's transmittance integral, so that
// the weights of a ray sum to ∫₀ˢ exp(−σt t) dt up to float rounding and an unshadowed medium is
// integrated exactly). What the renderer's pass adds: the visible fraction from their sum.
#ifndef MSM_RAY_MARCH_H
#define MSM_RAY_MARCH_H
#include "msm/scattering.h"
#include "msm/shared.h"

MSM_BEGIN

// The visible fraction of a ray from the weighted sum of its samples' visibility (in [0, 1]); a
// ray of length 0 has nothing to hide and counts as fully visible.
MSM_FN float msm_ray_march_visible_fraction(float weighted_visibility, float extinction, float length) {
  const float total = msm_transmittance_integral(extinction, 0.0f, length);
  return total > 0.0f ? msm_saturate(weighted_visibility / total) : 1.0f;
}

MSM_END

#endif // MSM_RAY_MARCH_H
