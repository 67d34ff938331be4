// scattering: single scattering in the scene's homogeneous medium along each view ray (JCGT 2017
// §5.1.1) with exact visibility: the transmittance-weighted visible fraction of each light l,
//   V̄_l = ∫₀ˢ exp(−σt t) V_l(c + t d) dt / ∫₀ˢ exp(−σt t) dt,
// by shadow rays from distances t drawn in proportion to σt exp(−σt t) on [0, s] (the truncated
// exponential, inverted in closed form), stratified in [0, 1): the estimator of V̄_l is then the
// plain mean of the V_l(t_i). Every light is tested at the same distances (one shadow ray per light
// and distance). The radiance is msm/scattering.h's sum over the lights, from the V̄_l.
#include <cmath>
#include <vector>

#include "internal.h"
#include "msm/scattering.h"

namespace msm::reference::detail {

ScatteringSample scattering_along_ray(const EffectContext& ctx, const scene::Medium& medium, const glm::dvec3& camera,
                                      const glm::dvec3& dir, double s, std::span<const ScatteringLight> lights,
                                      Rng& rng) {
  const int n = ctx.settings.samples;
  const bool stratified = ctx.settings.sampler == Sampler::stratified;
  const double sigma = medium.extinction;
  // The CDF of the truncated exponential is (1 − exp(−σ t)) / q, q = 1 − exp(−σ s); expm1 and
  // log1p keep it exact for optically thin rays (σ s down to 1e-300).
  const double q = -std::expm1(-sigma * s);
  double weight_sum = 0.0;
  for (const ScatteringLight& l : lights) weight_sum += l.weight;
  ScatteringSample r;
  std::vector<RunningStats> per_light(lights.size());
  RunningStats stats; // of the combined samples Σ w_l V_l(t) / Σ w_l (one light: V(t), 0 or 1)
  for (int i = 0; i < n; ++i) {
    const double u = stratified ? (i + rng.uniform()) / n : rng.uniform();
    const double t = q > 0.0 ? std::min(-std::log1p(-u * q) / sigma, s) : u * s;
    double combined = 0.0;
    for (std::size_t l = 0; l < lights.size(); ++l) {
      const double v = ctx.tracer.occluded(camera + t * dir, lights[l].towards_light) ? 0.0 : 1.0;
      per_light[l].add(v);
      combined += lights[l].weight * v;
    }
    stats.add(weight_sum > 0.0 ? combined / weight_sum : 1.0);
  }
  r.visible = stats.mean;
  for (const RunningStats& l : per_light) r.light_visible.push_back(l.mean);
  r.std_error = stats.std_error();
  r.samples = stats.n;
  r.rays = std::uint64_t(stats.n) * lights.size();
  return r;
}

} // namespace msm::reference::detail
