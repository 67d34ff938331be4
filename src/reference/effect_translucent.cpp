// translucent: transmittance of the hard light ray, the product of (1 - opacity) over every
// surface it crosses (constant material opacity; opacity textures are ignored).
#include "internal.h"

namespace msm::reference::detail {

EffectResult effect_translucent(const EffectContext& ctx, const SurfaceHit& hit, Rng&) {
    const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, ctx.towards_light);
    const Tracer::Transmission t = ctx.tracer.transmission(origin, ctx.towards_light, ctx.settings.max_crossings);
    EffectResult r;
    r.value = t.transmittance;
    r.rays = t.rays;
    return r;
}

}  // namespace msm::reference::detail
