// filtered: the hard shadow averaged over the footprint of the renderer's PCF kernel, with the
// kernel's offsets moved onto the receiver's tangent plane (the "receiver plane" reference).
#include <cmath>

#include "internal.h"

namespace msm::reference::detail {

EffectResult effect_filtered(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng) {
  const SampleSet set(ctx.settings.sampler, ctx.settings.samples);
  const glm::dvec3 travel = -ctx.towards_light;
  const double n_dot_travel = glm::dot(hit.normal, travel);
  RunningStats stats;
  for (int i = 0; i < set.count(); ++i) {
    const glm::dvec2 u = set.point(i, rng);
    const glm::dvec3 o_world = ctx.kernel.sample(u.x) * ctx.texel_x + ctx.kernel.sample(u.y) * ctx.texel_y;
    // Slide along the light direction back onto the tangent plane: dot(n, p' - p) = 0.
    const double limit = kMaxReceiverSlope * glm::length(o_world);
    double t = std::abs(n_dot_travel) > 0.0 ? -glm::dot(hit.normal, o_world) / n_dot_travel : 0.0;
    if (!std::isfinite(t)) t = 0.0;
    t = std::clamp(t, -limit, limit);
    const glm::dvec3 q = hit.p + o_world + t * travel;
    const double scale = std::max(hit.scale, point_scale(q));
    const glm::dvec3 origin = offset_origin(q, hit.normal, scale, ctx.towards_light);
    stats.add(ctx.tracer.occluded(origin, ctx.towards_light) ? 0.0 : 1.0);
  }
  return monte_carlo_result(stats);
}

} // namespace msm::reference::detail
