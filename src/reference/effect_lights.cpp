// hard, soft, translucent and filtered over every light of a scene with spot or point lights: the visibility of each light
// at the visible point (one shadow ray per light that lights it, or `samples` rays over its extent)
// and the direct light they bring.
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "internal.h"
#include "msm/shading.h"

namespace msm::reference::detail {

namespace {

// One light as the point p sees it: the irradiance E on a surface facing it, the unit direction
// towards it (its centre), how far a shadow ray runs (infinity for a directional light) and, for a
// light of some extent, the cosine of the half-angle of the cone it fills (1: a point).
struct LightAtPoint {
  glm::dvec3 irradiance{0.0}, towards{0.0, 1.0, 0.0};
  double distance = std::numeric_limits<double>::infinity();
  double cos_alpha = 1.0;
  double radius = 0.0; // a sphere's (spot and point lights)
};

LightAtPoint at_point(const scene::DirectionalLight& light, bool soft) {
  LightAtPoint l{glm::dvec3(light.irradiance), glm::normalize(glm::dvec3(light.towards_light))};
  if (soft) l.cos_alpha = std::cos(glm::radians(double(light.angular_extent_deg)) / 2.0);
  return l;
}

LightAtPoint at_point(const scene::LocalLight& light, const glm::dvec3& p, bool soft) {
  const glm::dvec3 to = glm::dvec3(light.position) - p;
  const double distance = glm::length(to);
  LightAtPoint l{glm::dvec3(light.irradiance_at(glm::vec3(p))),
                 distance > 0.0 ? to / distance : glm::dvec3(0.0, 1.0, 0.0), distance};
  if (soft && light.radius > 0.0f) {
    l.radius = light.radius;
    // A sphere of radius r at distance d fills the cone of sin α = r / d; from inside it, the
    // hemisphere towards its centre.
    const double s = std::min(double(light.radius) / std::max(distance, 1e-300), 1.0);
    l.cos_alpha = std::sqrt(std::max(0.0, 1.0 - s * s));
  }
  return l;
}

// Any unit vector orthogonal to n, and the third axis of a right-handed basis.
void basis(const glm::dvec3& n, glm::dvec3& x, glm::dvec3& y) {
  const glm::dvec3 a = std::abs(n.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
  x = glm::normalize(glm::cross(a, n));
  y = glm::cross(n, x);
}

} // namespace

LightsSample trace_lights(const EffectContext& ctx, const SurfaceHit& hit, const glm::dvec3& n, Rng& rng) {
  const scene::Scene& scene = ctx.tracer.scene();
  const bool soft = ctx.settings.effect == Effect::soft;
  const bool translucent = ctx.settings.effect == Effect::translucent;
  const bool filtered = ctx.settings.effect == Effect::filtered;
  const int samples = soft ? ctx.settings.samples : 1;
  const SampleSet set(ctx.settings.sampler, samples);
  // The geometric normal on the viewer's side: light from below it is blocked by the surface.
  const glm::dvec3 face = glm::dot(hit.normal, hit.incoming) > 0.0 ? -hit.normal : hit.normal;
  LightsSample out;
  out.samples = samples;
  std::vector<double> per_sample(std::size_t(samples), 0.0); // Σ_l lum(E_l) (its lit in this sample)
  glm::dvec3 lit_sum{0.0};                                   // Σ_l lum(E_l) lit_l (per channel)
  double unoccluded_sum = 0.0;                               // Σ_l lum(E_l) lit0_l
  bool first = true;
  double filtered_variance = 0.0; // of Σ_l lum(E_l) lit_l, the lights' estimates independent
  const auto add = [&](const LightAtPoint& l, const scene::LocalLight* local) {
    const double n_dot_l = glm::dot(n, l.towards);
    if (first) out.n_dot_l = n_dot_l;
    first = false;
    const double luminance = double(msm_luminance(glm::vec3(l.irradiance)));
    if (!(luminance > 0.0)) return; // no light arrives: nothing to trace
    // lit = ∫ max(n·ω, 0) V dω over the light's cone / (π sin² α): max(n·l, 0) V for a point;
    // uniform cone samples weigh 2 π (1 − cos α) / (π sin² α) = 2 / (1 + cos α) each.
    const bool point = l.cos_alpha >= 1.0;
    const int count = point ? 1 : samples;
    const double weight = (point ? 1.0 : 2.0 / (1.0 + l.cos_alpha)) / count;
    glm::dvec3 x, y;
    basis(l.towards, x, y);
    glm::dvec3 lit{0.0}; // per channel: translucent occluders pass some of each
    double unoccluded = 0.0;
    for (int i = 0; i < count; ++i) {
      glm::dvec3 d = l.towards;
      if (!point) {
        const glm::dvec2 a = set.point(i, rng);
        const double cos_t = 1.0 - a.x * (1.0 - l.cos_alpha), sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
        const double phi = 2.0 * std::numbers::pi * a.y;
        d = glm::normalize(cos_t * l.towards + sin_t * (std::cos(phi) * x + std::sin(phi) * y));
      }
      const double c = glm::dot(n, d);
      if (!(c > 0.0) || glm::dot(face, d) <= 0.0) continue;
      unoccluded += weight * c;
      const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, d);
      // To the light's surface (its centre for a point, nothing for a directional light).
      double tfar = l.distance;
      if (std::isfinite(tfar)) {
        const glm::dvec3 centre = hit.p + l.distance * l.towards, to = centre - origin;
        const double b = glm::dot(d, to), far2 = glm::dot(to, to) - l.radius * l.radius;
        tfar = far2 > 0.0 ? b - std::sqrt(std::max(0.0, b * b - far2)) : 0.0;
      }
      if (translucent) {
        const Tracer::Transmission t = ctx.tracer.transmission(origin, d, ctx.settings.max_crossings, tfar);
        out.rays += t.rays;
        lit += weight * c * t.channels;
        continue;
      }
      if (filtered) { // the light's own filtered map (ctx.frame: the first directional light's)
        const EffectResult f =
            local ? filtered_local_visibility(ctx, hit, *local, rng) : effect_filtered(ctx, hit, rng);
        out.rays += f.rays;
        lit += weight * c * f.value;
        filtered_variance += std::pow(luminance * weight * c * f.std_error, 2);
        continue;
      }
      ++out.rays;
      if (tfar > 0.0 && ctx.tracer.occluded(origin, d, tfar)) continue;
      lit += weight * c;
      if (!point) per_sample[std::size_t(i)] += luminance * count * weight * c; // its mean: luminance × lit
    }
    if (point) // the same in every sample
      for (double& v : per_sample) v += luminance * lit.r;
    out.direct += glm::dvec3(msm_direct_light(glm::vec3(l.irradiance), 1.0f, glm::vec3(lit)));
    lit_sum += luminance * lit;
    unoccluded_sum += luminance * unoccluded;
  };
  for (const scene::DirectionalLight& l : scene.lights) add(at_point(l, soft), nullptr);
  for (const scene::LocalLight& l : scene.local_lights) add(at_point(l, hit.p, soft), &l);
  out.visible_rgb = unoccluded_sum > 0.0 ? lit_sum / unoccluded_sum : glm::dvec3(0.0);
  // The mean, written so that three equal channels give exactly that value.
  const glm::dvec3& v = out.visible_rgb;
  out.visible = v.r + ((v.g - v.r) + (v.b - v.r)) / 3.0;
  if (filtered) {
    out.samples = ctx.settings.samples;
    if (unoccluded_sum > 0.0) out.std_error = std::sqrt(filtered_variance) / unoccluded_sum;
  }
  if (unoccluded_sum > 0.0 && samples > 1) {
    RunningStats stats;
    for (double v : per_sample) stats.add(v / unoccluded_sum);
    out.std_error = stats.std_error();
  }
  return out;
}

} // namespace msm::reference::detail
