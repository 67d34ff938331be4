// Single scattering in a homogeneous medium (JCGT 2017 §5.1.1), written once for the renderer's
// shaders, the ray tracer's ground truth and the tests. Radiance reaching the camera through a
// view ray of length s that starts at the camera p and runs along the unit direction ω_p:
//   exp(−σt s) L_s + f(ω_l, ω_p) E_l ∫₀ˢ exp(−σt t) V(p + t ω_p) dt
// with L_s the surface radiance at the end of the ray, E_l the light's irradiance, V the light's
// visibility and f(ω_l, ω_p) = ρ σt p(cos θ): the scattering coefficient σs = ρ σt (ρ the
// scattering albedo) times a phase function p normalized over the sphere (∫ p dω = 1, units 1/sr).
// θ is the scattering angle between the light's direction of travel and the direction the
// scattered light travels, towards the camera (−ω_p): cos θ = dot(towards_light, ω_p). Henyey–
// Greenstein with g > 0 scatters forwards, so looking into the light is brightest; g = 0 is
// isotropic, 1/(4π).
#ifndef MSM_SCATTERING_H
#define MSM_SCATTERING_H
#include "msm/shared.h"

MSM_BEGIN

// Henyey–Greenstein phase function, (1 − g²) / (4π (1 + g² − 2 g cos θ)^(3/2)).
// Precondition: −1 < g < 1 (the scene loader refuses others), cos θ in [−1, 1].
MSM_FN float msm_phase_henyey_greenstein(float cos_theta, float g) {
  const float denominator = max(1.0f + g * g - 2.0f * g * cos_theta, 1e-12f);
  return (1.0f - g * g) / (4.0f * MSM_PI * denominator * sqrt(denominator));
}

// f(ω_l, ω_p) of the radiance above: ρ σt p(cos θ); cos_theta = dot(towards_light, view direction).
MSM_FN float msm_scattering_phase_term(float extinction, float albedo, float g, float cos_theta) {
  return albedo * extinction * msm_phase_henyey_greenstein(cos_theta, g);
}

// (1 − exp(−x)) / x for x >= 0 without the cancellation of 1 − exp(−x) at small x (GLSL has no
// expm1): a Taylor series below 1e-2 (its first dropped term, x⁴/120, is below float rounding).
MSM_FN float msm_one_minus_exp_over_x(float x) {
  if (x < 1e-2f) return 1.0f - x * (0.5f - x * (1.0f / 6.0f - x * (1.0f / 24.0f)));
  return (1.0f - exp(-x)) / x;
}

// ∫_a^b exp(−σt t) dt = [−exp(−σt t) / σt]_a^b for 0 <= a <= b: the transmittance-weighted length
// of a segment of a view ray (the weights w(u, v) of §5.1.1 and the maximal scattering of a ray).
// Precondition: σt > 0.
MSM_FN float msm_transmittance_integral(float extinction, float a, float b) {
  const float segment = max(b - a, 0.0f);
  return exp(-extinction * a) * segment * msm_one_minus_exp_over_x(extinction * segment);
}

// The radiance at the camera of a ray of length s ending on a surface of radiance L_s, given the
// visible fraction of its in-scattering (1 everywhere lit, 0 everywhere shadowed):
//   exp(−σt s) L_s + f E_l visible_fraction ∫₀ˢ exp(−σt t) dt.
MSM_FN vec3 msm_scattered_radiance(vec3 surface_radiance, vec3 irradiance, float extinction, float phase_term, float s,
                                   float visible_fraction) {
  return exp(-extinction * s) * surface_radiance +
         (phase_term * visible_fraction * msm_transmittance_integral(extinction, 0.0f, s)) * irradiance;
}

MSM_END

#endif // MSM_SCATTERING_H
