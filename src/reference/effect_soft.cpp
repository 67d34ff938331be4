// soft: the fraction of a directional area light (a disc or a rectangle in the plane at unit
// distance along towards_light) that the visible point sees.
#include <cmath>

#include "internal.h"

namespace msm::reference::detail {

EffectResult effect_soft(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng) {
  const SampleSet set(ctx.settings.sampler, ctx.settings.samples);
  const bool disc = ctx.settings.light_shape == LightShape::disc;
  // The origin is on the side of the surface facing the light's centre (as in `hard`); sampled
  // directions below that side's horizon cross the surface itself and are blocked.
  const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, ctx.towards_light);
  RunningStats stats;
  // Directions of a batch first, then the rays (as effect_filtered, and why: kSampleBatch).
  glm::dvec3 dirs[kSampleBatch];
  for (int first = 0; first < set.count(); first += kSampleBatch) {
    const int n = std::min(kSampleBatch, set.count() - first);
    for (int k = 0; k < n; ++k) {
      const glm::dvec2 u = set.point(first + k, rng);
      const glm::dvec2 ab = disc ? ctx.half_x * concentric_disc(u)
                                 : glm::dvec2((2.0 * u.x - 1.0) * ctx.half_x, (2.0 * u.y - 1.0) * ctx.half_y);
      dirs[k] = glm::normalize(ctx.towards_light + ab.x * ctx.light_x + ab.y * ctx.light_y);
    }
    glm::dvec3 origins[kSampleBatch];
    bool blocked[kSampleBatch];
    for (int k = 0; k < n; ++k) origins[k] = origin;
    ctx.tracer.occluded(origins, dirs, n, blocked);
    for (int k = 0; k < n; ++k) stats.add(blocked[k] ? 0.0 : 1.0);
  }
  return monte_carlo_result(stats);
}

} // namespace msm::reference::detail
