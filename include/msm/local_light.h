// Spot and point lights (glTF KHR_lights_punctual): the irradiance a point source of radiant
// intensity I (W/sr) gives a surface facing it, the one formula the shading and the ray tracer
// (msm::scene::LocalLight::irradiance_at) share.
#ifndef MSM_LOCAL_LIGHT_H
#define MSM_LOCAL_LIGHT_H
#include "msm/shared.h"

MSM_BEGIN

// The smallest squared distance the inverse-square law is evaluated at (0.1 mm, squared): a
// surface through the light's position gets a large but finite irradiance, never inf or NaN
// (intensities up to 1e27 W/sr give at most 1e35).
const float MSM_LOCAL_LIGHT_MIN_DISTANCE2 = 1e-8f;

// glTF KHR_lights_punctual's spot cone: 1 within the inner half-angle, 0 beyond the outer, between
// them the square of the linear ramp in the cosine of the angle off the spot's axis. Equal cones:
// a hard edge. A point light: cos_outer = cos_inner = -1, 1 everywhere.
MSM_FN float msm_spot_cone(float cos_angle, float cos_outer, float cos_inner) {
  if (cos_inner <= cos_outer) return cos_angle >= cos_outer ? 1.0f : 0.0f;
  float t = clamp((cos_angle - cos_outer) / (cos_inner - cos_outer), 0.0f, 1.0f);
  return t * t;
}

// Irradiance on a surface facing the light at `distance` from it, `cos_angle` off the spot's axis:
// intensity / distance² times the cone's falloff, 0 beyond `range` (the light ends there).
MSM_FN vec3 msm_local_light_irradiance(vec3 intensity, float distance, float range, float cos_angle, float cos_outer,
                                       float cos_inner) {
  if (distance > range) return vec3(0.0f);
  float cone = msm_spot_cone(cos_angle, cos_outer, cos_inner);
  return intensity * (cone / max(distance * distance, MSM_LOCAL_LIGHT_MIN_DISTANCE2));
}

// A local light's shadow-map depth: the radial distance over the range (docs/techniques.md, "Light
// kinds"), not a perspective z / w, whose precision crowds at the near plane.
MSM_FN float msm_local_light_depth(float distance, float range) { return distance / range; }

// A receiver's depth in that convention less the depth bias, twice: once in [0,1] depth as the
// directional light's, since the map rounds distance / range to the same steps (1.5e-5 of the range
// in 16 bits: the techniques' biases in config.h were derived to exceed them), and once relative to
// the map's width where the receiver is, width_per_distance × distance (2 tan of the map's
// half-angle: 2 for a cube map's face), which grows with the texel's world size. The second alone
// is below half a 16-bit step (7.6e-6) nearer the light than 7.6e-6 × range / (width_per_distance ×
// bias): 4.7 m for PCF's 2e-5, a cube face and a 25 m range, where the rounded depths shadowed the
// receiver in rings of equal distance.
MSM_FN float msm_local_light_receiver_depth(float distance, float range, float bias, float width_per_distance) {
  return msm_local_light_depth(distance - bias * width_per_distance * distance, range) - bias;
}

MSM_END

#endif
