// soft: the fraction of a directional area light (a disc or a rectangle in the plane at unit
// distance along towards_light) that the visible point sees, and the light's cosine-weighted
// visibility for the radiance (reference.h).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "internal.h"
#include "msm/light_probe.h"

namespace msm::reference::detail {

namespace {

// ∫ (d·L) dω over the light, the irradiance of radiance 1 on a surface facing it: π sin² α for the
// disc of radius tan α, and for the rectangle [−X, X] x [−Y, Y] at unit distance the integral of
// (1 + a² + b²)^−2 da db in closed form (msm/light_probe.h; checked against a midpoint rule).
double facing_integral(bool disc, double half_x, double half_y) {
  if (disc) {
    const double s = std::sin(std::atan(half_x));
    return std::numbers::pi * s * s;
  }
  return double(msm_rect_light_facing_integral(glm::vec2(float(half_x), float(half_y))));
}

} // namespace

EffectResult effect_soft(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng) {
  const SampleSet set(ctx.settings.sampler, ctx.settings.samples);
  const bool disc = ctx.light_shape == LightShape::disc;
  // The origin is on the side of the surface facing the light's centre (as in `hard`); sampled
  // directions below that side's horizon cross the surface itself and are blocked.
  const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, ctx.towards_light);
  // The radiance's normal: the interpolated one turned towards the viewer (reference.cpp).
  glm::dvec3 n = ctx.tracer.shading_normal(hit);
  if (glm::dot(hit.normal, hit.incoming) > 0.0) n = -n;
  const double n_dot_l = glm::dot(n, ctx.towards_light);
  // The light reaches the viewer's side of the surface: where the light's centre is below that
  // side's horizon, `lit` traces its own rays from there.
  const glm::dvec3 viewer_side = offset_origin(hit.p, hit.normal, hit.scale, -hit.incoming);
  const bool same_side = viewer_side == origin;
  std::uint64_t extra_rays = 0;
  // Directions are uniform over the light's area in the plane at unit distance: one of them stands
  // for area / cos³ θ of solid angle (θ its angle off L).
  const double area = disc ? std::numbers::pi * ctx.half_x * ctx.half_x : 4.0 * ctx.half_x * ctx.half_y;
  const double facing = facing_integral(disc, ctx.half_x, ctx.half_y);
  // Directions of a batch first, then the rays (as effect_filtered, and why: kSampleBatch). The
  // points come from the generator in double precision (the same random numbers in the same
  // order), the directions in single precision, which is what Embree traces: the loops over a
  // whole batch have no conditional and no call, and the compiler vectorizes them.
  const float half_x = float(ctx.half_x), half_y = float(ctx.half_y);
  const glm::vec3 towards(ctx.towards_light), light_x(ctx.light_x), light_y(ctx.light_y);
  alignas(64) float ux[kSampleBatch], uy[kSampleBatch], dx[kSampleBatch], dy[kSampleBatch], dz[kSampleBatch];
  bool blocked[kSampleBatch], lit_blocked[kSampleBatch];
  int unblocked = 0;
  double deviation = 0.0;
  for (int first = 0; first < set.count(); first += kSampleBatch) {
    const int count = std::min(kSampleBatch, set.count() - first);
    for (int k = 0; k < count; ++k) {
      const glm::dvec2 u = set.point(first + k, rng);
      ux[k] = float(u.x);
      uy[k] = float(u.y);
    }
    std::fill(ux + count, ux + kSampleBatch, 0.5f); // a last, partial batch: directions not traced
    std::fill(uy + count, uy + kSampleBatch, 0.5f);
    if (disc) {
      for (int k = 0; k < kSampleBatch; ++k) {
        const glm::vec2 p = concentric_disc(glm::vec2(ux[k], uy[k]));
        ux[k] = half_x * p.x;
        uy[k] = half_x * p.y;
      }
    } else {
      for (int k = 0; k < kSampleBatch; ++k) {
        ux[k] = (2.0f * ux[k] - 1.0f) * half_x;
        uy[k] = (2.0f * uy[k] - 1.0f) * half_y;
      }
    }
    for (int k = 0; k < kSampleBatch; ++k) {
      // The frame is orthonormal, so |d|² = 1 + a² + b² (and a light of no area traces exactly
      // towards_light, as `hard` does).
      const glm::vec3 d = towards + ux[k] * light_x + uy[k] * light_y;
      const float inverse_length = 1.0f / std::sqrt(1.0f + ux[k] * ux[k] + uy[k] * uy[k]);
      dx[k] = d.x * inverse_length;
      dy[k] = d.y * inverse_length;
      dz[k] = d.z * inverse_length;
    }
    ctx.tracer.occluded(origin, dx, dy, dz, count, blocked);
    if (same_side) {
      std::copy(blocked, blocked + count, lit_blocked);
    } else {
      ctx.tracer.occluded(viewer_side, dx, dy, dz, count, lit_blocked);
      extra_rays += std::uint64_t(count);
    }
    for (int k = 0; k < count; ++k) {
      unblocked += blocked[k] ? 0 : 1;
      // ∫ max(n·d, 0) V dω = (n·L) ∫ (d·L) dω + ∫ (max(n·d, 0) V − n·d) dω (the light is symmetric
      // about L, so ∫ d dω is along L): only the second integral is sampled, and it is exactly 0
      // where the whole light is visible and above the horizon.
      const glm::dvec3 d(dx[k], dy[k], dz[k]);
      const double cos_n = glm::dot(n, d), cos_l = glm::dot(ctx.towards_light, d);
      deviation += ((lit_blocked[k] ? 0.0 : std::max(cos_n, 0.0)) - cos_n) * cos_l * cos_l * cos_l;
    }
  }
  EffectResult r = monte_carlo_result(BinaryStats{set.count(), unblocked});
  r.rays += extra_rays;
  // A light of no area is the point light of `hard`.
  r.lit = facing > 0.0 ? std::max(n_dot_l + area * deviation / (set.count() * facing), 0.0)
                       : std::max(n_dot_l, 0.0) * r.value;
  return r;
}

} // namespace msm::reference::detail
