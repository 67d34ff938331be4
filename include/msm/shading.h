// The look of every image msm makes, defined once for the renderer's shaders, the ray tracer's
// radiance and the tools: Lambertian surfaces lit by directional lights plus a constant ambient
// term, Narkowicz's ACES fit as the tone curve, and the sky colour of pixels without a surface.
//   radiance = albedo (Σ_l E_l max(n·l_l, 0) V_l / π + ambient)
// with E_l the irradiance of light l on a surface facing it, V_l its visibility (per colour
// channel for coloured translucent shadows) and ambient MSM_AMBIENT (an irradiance factor, so
// that shadowed surfaces keep a little of their albedo).
#ifndef MSM_SHADING_H
#define MSM_SHADING_H
#include "msm/shared.h"

MSM_BEGIN

const float MSM_AMBIENT = 0.03f;
// Linear RGB radiance of pixels where the camera sees no surface.
const vec3 MSM_SKY_RADIANCE = vec3(0.55f, 0.65f, 0.8f);

// Reflected-irradiance term of one directional light: E max(n·l, 0) V / π (the 1/π of the
// Lambertian BRDF; the albedo multiplies the sum over lights in msm_surface_radiance).
MSM_FN vec3 msm_direct_light(vec3 irradiance, float n_dot_l, vec3 visibility) {
  return irradiance * (max(n_dot_l, 0.0f) * visibility / MSM_PI);
}

// Outgoing radiance of a Lambertian surface from the summed direct terms and the ambient factor.
MSM_FN vec3 msm_surface_radiance(vec3 albedo, vec3 direct, float ambient) { return albedo * (direct + ambient); }

// Relative luminance (CIE Y) of linear Rec. 709 / sRGB: weights lights and colours wherever one
// number has to stand for a colour (the shadow buffer of several lights, metrics, light probes).
// Products and sums in this order, none fused (precise; C++ builds with -ffp-contract=off): the
// light probe's fixed-point tables (light_probe.h) need the same bits on every device and the CPU.
MSM_FN float msm_luminance(vec3 rgb) {
  MSM_PRECISE float y = rgb.x * 0.2126f + rgb.y * 0.7152f + rgb.z * 0.0722f;
  return y;
}

// The curve below reaches 1 at x = (0.56 + sqrt(0.56² + 4 · 0.08 · 0.14)) / 0.16 ≈ 7.24 and exceeds it
// above, where the clamp makes it 1: x is capped at this value first, which changes no result and
// keeps x² finite (in single precision x² overflowed above ~1.16e19: inf / inf, NaN, a black pixel
// where the surface is brightest).
const float MSM_ACES_SATURATION = 16.0f;

// Narkowicz 2015 fit of the ACES filmic curve, x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14),
// clamped to [0, 1]; applied after the exposure. Precondition: x >= 0 and not NaN (callers map
// NaN and negative values first where they can occur); +inf gives 1.
MSM_FN float msm_aces(float x) {
  x = min(x, MSM_ACES_SATURATION);
  return clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}
MSM_FN vec3 msm_aces(vec3 x) {
  x = min(x, vec3(MSM_ACES_SATURATION));
  return clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), vec3(0.0f), vec3(1.0f));
}

// The radiance x >= 0 that msm_aces maps to y in [0, 1) (the positive root of
// (2.51 − 2.43 y) x² + (0.03 − 0.59 y) x − 0.14 y = 0): the background's radiance where a frame
// composites over linear radiance (the scattering techniques) and must still show the sky as before.
MSM_FN float msm_aces_inverse(float y) {
  const float a = 2.51f - 2.43f * y, b = 0.03f - 0.59f * y, c = -0.14f * y;
  return (-b + sqrt(max(b * b - 4.0f * a * c, 0.0f))) / (2.0f * a);
}

MSM_END

#endif // MSM_SHADING_H
