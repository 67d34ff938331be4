// scattering: single scattering in the scene's homogeneous medium along each view ray (JCGT 2017
// §5.1.1) with exact visibility: the transmittance-weighted visible fraction of the light,
//   V̄ = ∫₀ˢ exp(−σt t) V(c + t d) dt / ∫₀ˢ exp(−σt t) dt,
// by shadow rays from distances t drawn in proportion to σt exp(−σt t) on [0, s] (the truncated
// exponential, inverted in closed form), stratified in [0, 1): the estimator of V̄ is then the
// plain mean of the V(t_i). The radiance is msm/scattering.h's, from V̄.
#include <cmath>

#include "internal.h"
#include "msm/scattering.h"

namespace msm::reference::detail {

ScatteringSample scattering_along_ray(const EffectContext& ctx, const scene::Medium& medium, const glm::dvec3& camera,
                                      const glm::dvec3& dir, double s, Rng& rng) {
  const int n = ctx.settings.samples;
  const bool stratified = ctx.settings.sampler == Sampler::stratified;
  const double sigma = medium.extinction;
  // The CDF of the truncated exponential is (1 − exp(−σ t)) / q, q = 1 − exp(−σ s); expm1 and
  // log1p keep it exact for optically thin rays (σ s down to 1e-300).
  const double q = -std::expm1(-sigma * s);
  RunningStats stats;
  for (int i = 0; i < n; ++i) {
    const double u = stratified ? (i + rng.uniform()) / n : rng.uniform();
    const double t = q > 0.0 ? std::min(-std::log1p(-u * q) / sigma, s) : u * s;
    stats.add(ctx.tracer.occluded(camera + t * dir, ctx.towards_light) ? 0.0 : 1.0);
  }
  ScatteringSample r;
  r.visible = stats.mean;
  r.std_error = stats.std_error();
  r.samples = stats.n;
  r.rays = std::uint64_t(stats.n);
  return r;
}

} // namespace msm::reference::detail
