// filtered: what a filtered shadow map means, on any geometry: the PCF kernel over the light's
// shadow-map plane, each sampled light ray's visibility at the receiver's depth extrapolated along
// the renderer's receiver plane (within the plane's tolerance), surfaces turned away from the light
// in their own shadow (reference.h has the definition).
#include <cmath>

#include "internal.h"
#include "msm/render/frame.h"

namespace msm::reference::detail {

EffectResult effect_filtered(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng) {
  // The receiver as the renderer shades it: the interpolated normal, turned towards the viewer.
  glm::dvec3 n = ctx.tracer.shading_normal(hit);
  if (glm::dot(hit.normal, hit.incoming) > 0.0) n = -n;
  const double n_dot_l = glm::dot(n, ctx.towards_light);
  if (!(n_dot_l > 0.0)) {
    EffectResult turned_away; // in its own shadow, decided without sampling
    turned_away.value = 0.0;
    turned_away.samples = 0;
    turned_away.rays = 0;
    return turned_away;
  }
  // The plane's depth per texel along the map's x and y ([0,1] depth: world distance along the
  // light's travel over the map's depth range), clamped as the renderer clamps it.
  const double nx = glm::dot(n, ctx.frame.x_axis), ny = glm::dot(n, ctx.frame.y_axis);
  const double limit = double(MSM_MAX_RECEIVER_DEPTH_SLOPE);
  const glm::dvec2 slope = glm::clamp(glm::dvec2(nx * glm::length(ctx.texel_x), ny * glm::length(ctx.texel_y)) /
                                          (n_dot_l * ctx.frame.depth_extent),
                                      glm::dvec2(-limit), glm::dvec2(limit));
  const glm::dvec3 travel = -ctx.towards_light;
  const SampleSet set(ctx.settings.sampler, ctx.settings.samples);
  RunningStats stats;
  // The ray origins of a batch of samples first, then their rays: each sample's arithmetic is a
  // chain of dependent steps (two square roots), which the processor overlaps across the samples
  // of a batch but not across a call into Embree. The same random numbers in the same
  // order: the same rays as one sample at a time.
  glm::dvec3 origins[kSampleBatch];
  for (int first = 0; first < set.count(); first += kSampleBatch) {
    const int n = std::min(kSampleBatch, set.count() - first);
    for (int k = 0; k < n; ++k) {
      const glm::dvec2 u = set.point(first + k, rng);
      const glm::dvec2 o(ctx.kernel.sample(u.x), ctx.kernel.sample(u.y));
      const glm::dvec3 o_world = o.x * ctx.texel_x + o.y * ctx.texel_y;
      // The light ray through (x, y) + o at the plane's depth there; surfaces within the plane's
      // tolerance of that point are the receiver itself, so the ray starts beyond them.
      const glm::dvec3 q = hit.p + o_world + (glm::dot(slope, o) * ctx.frame.depth_extent) * travel;
      const double tolerance =
          kOffsetScale * std::max(hit.scale, point_scale(q)) + kReceiverPlaneTolerance * glm::length(o_world);
      origins[k] = q + tolerance * ctx.towards_light;
    }
    bool blocked[kSampleBatch];
    glm::dvec3 dirs[kSampleBatch];
    for (int k = 0; k < n; ++k) dirs[k] = ctx.towards_light;
    ctx.tracer.occluded(origins, dirs, n, blocked);
    for (int k = 0; k < n; ++k) stats.add(blocked[k] ? 0.0 : 1.0);
  }
  return monte_carlo_result(stats);
}

} // namespace msm::reference::detail
