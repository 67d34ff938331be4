// scattering: single scattering in the scene's homogeneous medium along each view ray (JCGT 2017
// §5.1.1) with exact visibility: the transmittance-weighted visible fraction of each light l,
//   V̄_l = ∫₀ˢ exp(−σt t) V_l(c + t d) dt / ∫₀ˢ exp(−σt t) dt,
// by shadow rays from distances t drawn in proportion to σt exp(−σt t) on [0, s] (the truncated
// exponential, inverted in closed form), stratified in [0, 1): the estimator of V̄_l is then the
// plain mean of the V_l(t_i). Every light is tested at the same distances (one shadow ray per light
// and distance). The radiance is msm/scattering.h's sum over the lights, from the V̄_l.
#include <algorithm>
#include <cmath>
#include <vector>

#include "internal.h"
#include "msm/scattering.h"

namespace msm::reference::detail {

namespace {

// Light l's weight w_l(t) and f E (rgb) at p: a directional light's are constant (its weight; its
// f E is applied by the caller), a local light's msm_local_light_inscattering.
struct LightAt {
  double weight;
  glm::dvec3 inscattering{0.0};
};
LightAt light_at(const ScatteringLight& l, const scene::Medium& m, const glm::dvec3& p, const glm::dvec3& dir) {
  if (!l.local) return {l.weight};
  const scene::LocalLight& light = *l.local;
  const glm::vec3 fe = msm_local_light_inscattering(glm::vec3(p), glm::vec3(dir), light.position, light.direction,
                                                    light.intensity, light.range, light.cos_outer(), light.cos_inner(),
                                                    m.extinction, m.scattering_albedo, m.g);
  return {double(msm_luminance(fe)), glm::dvec3(fe)};
}

// Whether light l reaches p: a directional light's ray runs to infinity, a local light's to it.
bool reaches(const Tracer& tracer, const ScatteringLight& l, const glm::dvec3& p) {
  if (!l.local) return !tracer.occluded(p, l.towards_light);
  const glm::dvec3 to = glm::dvec3(l.local->position) - p;
  const double d = glm::length(to);
  return !(d > 0.0) || !tracer.occluded(p, to / d, d);
}

} // namespace

ScatteringSample scattering_along_ray(const EffectContext& ctx, const scene::Medium& medium, const glm::dvec3& camera,
                                      const glm::dvec3& dir, double s, std::span<const ScatteringLight> lights,
                                      Rng& rng) {
  const int n = ctx.settings.samples;
  const bool stratified = ctx.settings.sampler == Sampler::stratified;
  const double sigma = medium.extinction;
  // The CDF of the truncated exponential is (1 − exp(−σ t)) / q, q = 1 − exp(−σ s); expm1 and
  // log1p keep it exact for optically thin rays (σ s down to 1e-300).
  const double q = -std::expm1(-sigma * s);
  ScatteringSample r;
  // Per light: Σ w_l(t) V_l(t), Σ w_l(t), Σ f E(t); per sample: Σ_l w_l V_l and Σ_l w_l.
  std::vector<double> lit(lights.size(), 0.0), unshadowed(lights.size(), 0.0);
  std::vector<glm::dvec3> inscattering(lights.size(), glm::dvec3(0.0));
  std::vector<double> sample_lit, sample_weight;
  for (int i = 0; i < n; ++i) {
    const double u = stratified ? (i + rng.uniform()) / n : rng.uniform();
    const double t = q > 0.0 ? std::min(-std::log1p(-u * q) / sigma, s) : u * s;
    const glm::dvec3 p = camera + t * dir;
    double a = 0.0, b = 0.0;
    for (std::size_t l = 0; l < lights.size(); ++l) {
      const LightAt at = light_at(lights[l], medium, p, dir);
      // Where a local light brings nothing (outside its cone, beyond its range) no ray is needed.
      const bool dark = lights[l].local && !(at.weight > 0.0);
      const double v = !dark && reaches(ctx.tracer, lights[l], p) ? 1.0 : 0.0;
      if (!dark) ++r.rays;
      // A light's own fraction: a directional light's the mean of V, a local light's weighted by f E.
      const double own = lights[l].local ? at.weight : 1.0;
      lit[l] += own * v;
      unshadowed[l] += own;
      inscattering[l] += at.inscattering;
      a += at.weight * v;
      b += at.weight;
    }
    sample_lit.push_back(a);
    sample_weight.push_back(b);
  }
  const auto ratio = [](double x, double y) { return y > 0.0 ? x / y : 1.0; };
  for (std::size_t l = 0; l < lights.size(); ++l) {
    r.light_visible.push_back(ratio(lit[l], unshadowed[l]));
    r.light_unshadowed.push_back(n > 0 ? inscattering[l] / double(n) : glm::dvec3(0.0));
  }
  // The combined visible fraction Σ w V / Σ w (a ratio of the samples' sums; constant weights: the
  // mean of Σ_l w_l V_l / Σ_l w_l) and its standard error (the ratio estimator's, by the delta method).
  double a_sum = 0.0, b_sum = 0.0;
  for (int i = 0; i < n; ++i) a_sum += sample_lit[size_t(i)], b_sum += sample_weight[size_t(i)];
  r.visible = ratio(a_sum, b_sum);
  RunningStats stats;
  const double b_mean = b_sum / std::max(n, 1);
  for (int i = 0; i < n; ++i)
    stats.add(b_mean > 0.0 ? (sample_lit[size_t(i)] - r.visible * sample_weight[size_t(i)]) / b_mean + r.visible : 1.0);
  r.std_error = stats.std_error();
  r.samples = stats.n;
  return r;
}

} // namespace msm::reference::detail
