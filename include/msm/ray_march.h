// Single scattering by ray marching (the baseline of JCGT 2017 §5.5.1): `count` equidistant
// samples along a view ray of length s, all shifted by one jitter in [0, 1) per pixel (blue noise
// in the renderer), each sample standing for its segment [i, i + 1) s / count. A sample's weight is
// its segment's transmittance integral ∫ exp(−σt t) dt (scattering.h), so the weights of a ray sum
// to ∫₀ˢ exp(−σt t) dt up to float rounding: a medium without occluders is integrated exactly, and
// the visible fraction is the weighted mean of the samples' visibility. The renderer's pass and
// the tests use these functions; the in-scattered radiance is then msm_scattered_radiance.
#ifndef MSM_RAY_MARCH_H
#define MSM_RAY_MARCH_H
#include "msm/scattering.h"
#include "msm/shared.h"

MSM_BEGIN

// Distance from the camera of sample i in [0, count) of a ray of length s, jitter in [0, 1).
MSM_FN float msm_ray_march_distance(float length, int count, int i, float jitter) {
  return (float(i) + jitter) * (length / float(count));
}

// Weight of sample i: ∫ exp(−σt t) dt over its segment. Precondition: σt > 0, count >= 1.
MSM_FN float msm_ray_march_weight(float extinction, float length, int count, int i) {
  const float step = length / float(count);
  return msm_transmittance_integral(extinction, float(i) * step, float(i + 1) * step);
}

// The visible fraction of a ray from the weighted sum of its samples' visibility (in [0, 1]); a
// ray of length 0 has nothing to hide and counts as fully visible.
MSM_FN float msm_ray_march_visible_fraction(float weighted_visibility, float extinction, float length) {
  const float total = msm_transmittance_integral(extinction, 0.0f, length);
  return total > 0.0f ? msm_saturate(weighted_visibility / total) : 1.0f;
}

MSM_END

#endif // MSM_RAY_MARCH_H
