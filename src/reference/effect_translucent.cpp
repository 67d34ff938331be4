// translucent: transmittance of the hard light ray per RGB channel, the product of
// (1 - channel opacity) over every surface it crosses (channel opacity = alpha * (1 -
// transmission_color), alpha = the material's constant times its opacity texture or noise), and
// its mean over the channels as the scalar visibility.
#include "internal.h"

namespace msm::reference::detail {

EffectResult effect_translucent(const EffectContext& ctx, const SurfaceHit& hit, Rng&) {
  const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, ctx.towards_light);
  const Tracer::Transmission t = ctx.tracer.transmission(origin, ctx.towards_light, ctx.settings.max_crossings);
  EffectResult r;
  r.value = t.transmittance;
  r.rgb = t.channels;
  r.rays = t.rays;
  return r;
}

} // namespace msm::reference::detail
