// hard: exact visibility of the directional light at the visible point (one shadow ray).
#include "internal.h"

namespace msm::reference::detail {

EffectResult effect_hard(const EffectContext& ctx, const SurfaceHit& hit, Rng&) {
  const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, ctx.towards_light);
  EffectResult r;
  r.value = ctx.tracer.occluded(origin, ctx.towards_light) ? 0.0 : 1.0;
  r.rays = 1;
  return r;
}

} // namespace msm::reference::detail
