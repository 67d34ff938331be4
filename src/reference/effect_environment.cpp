// environment: image-based lighting with exact visibility (reference.h, "environment"). The full
// probe is sampled in proportion to luminance x solid angle and the cosine-weighted hemisphere,
// combined by the balance heuristic; the extracted area lights (--probe-lights) and the scene's
// other directional lights are uniform cones (discs) or rectangles (Kneiphof §4.1.2). The texel geometry is msm/light_probe.h's.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "internal.h"
#include "msm/light_probe.h"
#include "msm/probe/probe.h"

namespace msm::reference::detail {
namespace {

constexpr double kPi = std::numbers::pi;

// Any unit vector orthogonal to n, and the third axis of a right-handed basis.
void basis(const glm::dvec3& n, glm::dvec3& x, glm::dvec3& y) {
  const glm::dvec3 a = std::abs(n.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
  x = glm::normalize(glm::cross(a, n));
  y = glm::cross(n, x);
}

ConeLight cone_light(const scene::Scene& scene, const scene::DirectionalLight& l) {
  ConeLight c;
  c.axis = glm::normalize(glm::dvec3(l.towards_light));
  if (l.rectangular()) {
    // The rectangle on the axes of the light's shadow-map frame (the renderer's spreads are
    // along them), made exactly orthonormal to the axis. Radiance L = E_f / F uniform in solid
    // angle: a uniform point of the plane rectangle (area A) has the density 1 / (A cos³ θ) in
    // solid angle, so f / pdf = E_f (A / F) cos³ θ (n·d).
    const scene::LightFrame f = scene.light_frame(l);
    c.rectangle = true;
    c.x = glm::normalize(f.x_axis - glm::dot(f.x_axis, c.axis) * c.axis);
    c.y = glm::cross(c.axis, c.x);
    const glm::vec2 t = l.tan_half_extents();
    c.half_x = t.x;
    c.half_y = t.y;
    // A / F is continuous down to a line or a point (a region one texel wide has no variance
    // along that axis), where both vanish: taken at extents of at least 1e-4 (off by ~1e-8).
    const glm::vec2 tf = glm::max(t, glm::vec2(1e-4f));
    c.estimate =
        glm::dvec3(l.irradiance) * (4.0 * double(tf.x) * double(tf.y) / double(msm_rect_light_facing_integral(tf)));
    return c;
  }
  basis(c.axis, c.x, c.y);
  c.cos_alpha = std::cos(glm::radians(double(l.angular_extent_deg)) / 2.0);
  // Radiance L = E_f / (π sin² α) over a cone of 2π (1 − cos α) sr: L / pdf = E_f 2 / (1 + cos α),
  // E_f itself at α = 0 (a point light: the cone's one direction).
  c.estimate = glm::dvec3(l.irradiance) * (2.0 / (1.0 + c.cos_alpha));
  return c;
}

double face_coordinate(int i, int m, double offset) { return (2.0 * (i + offset)) / m - 1.0; }

} // namespace

EnvironmentLighting::EnvironmentLighting(const scene::Scene& scene, bool probe_lights) {
  if (!scene.probe)
    throw std::invalid_argument("the environment effect needs a scene with a \"probe\" (scenes/README.md)");
  const scene::ProbeLighting& p = *scene.probe;
  const std::size_t first = p.first_light, last = std::min(scene.lights.size(), first + std::size_t(p.lights));
  // A probe light with sub-lights (the probe's "sub_lights"): the lights it stands for are its
  // sub-lights, each traced as the rectangle it is (the renderer shades their sum, shadowed by the
  // light's one shadow map: what this truth tells apart is that shadow).
  for (std::size_t k = 0; k < scene.lights.size(); ++k) {
    if (!probe_lights && k >= first && k < last) continue;
    const scene::DirectionalLight& l = scene.lights[k];
    if (l.sub_lights.empty())
      cones.push_back(cone_light(scene, l));
    else
      for (const scene::DirectionalLight& sub : l.sub_lights) cones.push_back(cone_light(scene, sub));
  }
  if (probe_lights) return;
  msm::probe::CubeMap cube;
  try {
    cube = msm::probe::load_probe(p.file.string(), p.size, p.rotation_deg, p.intensity);
  } catch (const msm::probe::ProbeError& e) { throw std::invalid_argument(e.what()); }
  size = cube.size;
  const int m = size;
  radiance.reserve(std::size_t(6) * m * m);
  cdf.reserve(radiance.capacity());
  double total = 0.0;
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const glm::vec3 L = cube.at(face, i, j);
        radiance.push_back(L);
        total += double(msm_luminance(L)) *
                 msm_cube_texel_weight(float(face_coordinate(i, m, 0.5)), float(face_coordinate(j, m, 0.5)), float(m));
        cdf.push_back(total);
      }
  if (total > 0.0)
    for (double& c : cdf) c /= total;
  else
    cdf.clear(); // a black probe: only the cosine samples (which find no light)
}

EnvironmentSample environment_irradiance(const EffectContext& ctx, const EnvironmentLighting& lighting,
                                         const SurfaceHit& hit, const glm::dvec3& n, const glm::dvec3& view, Rng& rng) {
  const int count = ctx.settings.samples;
  const SampleSet set(ctx.settings.sampler, count);
  const glm::dvec3 facing = glm::dot(hit.normal, view) > 0.0 ? -hit.normal : hit.normal;
  EnvironmentSample out;
  // V(ω): directions below the geometric horizon cross the surface itself.
  const auto visible = [&](const glm::dvec3& d) {
    if (glm::dot(facing, d) <= 0.0) return false;
    ++out.rays;
    return !ctx.tracer.occluded(offset_origin(hit.p, hit.normal, hit.scale, d), d);
  };
  const int m = lighting.size;
  const bool probe = !lighting.cdf.empty();
  const auto probability = [&](std::size_t t) { return lighting.cdf[t] - (t ? lighting.cdf[t - 1] : 0.0); };
  // Solid-angle density of the probe sampler at a point (u, v) of texel t: the texel's
  // probability over its area 4 / m² on the face plane, times the plane's dA / dω.
  const auto probe_pdf = [&](std::size_t t, double u, double v) {
    return probability(t) / double(msm_cube_texel_weight(float(u), float(v), float(m)));
  };
  glm::dvec3 tx, ty;
  basis(n, tx, ty);
  RunningStats stats;
  glm::dvec3 sum(0.0), sum0(0.0);
  for (int i = 0; i < count; ++i) {
    glm::dvec3 value(0.0), value0(0.0);
    const auto add = [&](const glm::dvec3& f, const glm::dvec3& d) {
      value0 += f;
      if (visible(d)) value += f;
    };
    if (probe) {
      // Probe sample: the texel by the first coordinate, the point inside it by what is left of it and the second.
      const glm::dvec2 a = set.point(i, rng);
      const std::size_t t =
          std::min<std::size_t>(std::upper_bound(lighting.cdf.begin(), lighting.cdf.end(), a.x) - lighting.cdf.begin(),
                                lighting.cdf.size() - 1);
      const double p = probability(t);
      const double s = p > 0.0 ? std::clamp((a.x - (lighting.cdf[t] - p)) / p, 0.0, 1.0) : 0.5;
      const int face = int(t / (std::size_t(m) * m)), j = int(t / m % m), k = int(t % m);
      const double u = face_coordinate(k, m, s), v = face_coordinate(j, m, a.y);
      const glm::dvec3 d = glm::normalize(glm::dvec3(msm_cube_direction(face, float(u), float(v))));
      const double c = glm::dot(n, d);
      if (c > 0.0) add(glm::dvec3(lighting.radiance[t]) * (c / (probe_pdf(t, u, v) + c / kPi)), d);
      // Cosine sample.
      const glm::dvec2 b = concentric_disc(set.point(i, rng));
      const double z = std::sqrt(std::max(0.0, 1.0 - b.x * b.x - b.y * b.y));
      const glm::dvec3 e = glm::normalize(b.x * tx + b.y * ty + z * n);
      const double ce = glm::dot(n, e);
      if (ce > 0.0) {
        const MsmCubeCoord q = msm_cube_coord(glm::vec3(e));
        const int qi = std::clamp(int((q.uv.x + 1.0f) * 0.5f * m), 0, m - 1);
        const int qj = std::clamp(int((q.uv.y + 1.0f) * 0.5f * m), 0, m - 1);
        const std::size_t te = (std::size_t(q.face) * m + qj) * m + qi;
        add(glm::dvec3(lighting.radiance[te]) * (ce / (probe_pdf(te, q.uv.x, q.uv.y) + ce / kPi)), e);
      }
    }
    for (const ConeLight& l : lighting.cones) {
      const glm::dvec2 a = set.point(i, rng);
      if (l.rectangle) {
        const glm::dvec3 p = l.axis + (2.0 * a.x - 1.0) * l.half_x * l.x + (2.0 * a.y - 1.0) * l.half_y * l.y;
        const double r = glm::length(p);
        const glm::dvec3 d = p / r;
        const double c = glm::dot(n, d);
        if (c > 0.0) add(l.estimate * (c / (r * r * r)), d); // cos θ = 1 / r
        continue;
      }
      const double cos_t = 1.0 - a.x * (1.0 - l.cos_alpha), sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
      const double phi = 2.0 * kPi * a.y;
      const glm::dvec3 d = glm::normalize(cos_t * l.axis + sin_t * (std::cos(phi) * l.x + std::sin(phi) * l.y));
      const double c = glm::dot(n, d);
      if (c > 0.0) add(l.estimate * c, d);
    }
    sum += value;
    sum0 += value0;
    stats.add(double(msm_luminance(glm::vec3(value))));
  }
  out.irradiance = sum / double(count);
  out.unoccluded = sum0 / double(count);
  out.std_error = stats.std_error();
  out.samples = count;
  return out;
}

} // namespace msm::reference::detail
