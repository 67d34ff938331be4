// environment: image-based lighting with exact visibility (reference.h, "environment"). The full
// probe is sampled in proportion to its luminance above its mean x solid angle and the
// cosine-weighted hemisphere, combined by the balance heuristic; the extracted area lights
// (--extracted-lights) and the scene's other directional lights are uniform cones (discs) or
// rectangles (Kneiphof §4.1.2). The texel geometry is msm/light_probe.h's.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <vector>

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

std::atomic<ProbeSampling> sampling_in_use{ProbeSampling::compensated};

} // namespace

void set_probe_sampling(ProbeSampling sampling) { sampling_in_use = sampling; }
ProbeSampling probe_sampling() { return sampling_in_use; }

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
  sampling = probe_sampling();
  const int m = size;
  const std::size_t texels = std::size_t(6) * m * m;
  radiance.reserve(texels);
  std::vector<double> luminance, weight;
  luminance.reserve(texels);
  weight.reserve(texels);
  double energy = 0.0, solid_angle = 0.0;
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const glm::vec3 L = cube.at(face, i, j);
        radiance.push_back(L);
        luminance.push_back(double(msm_luminance(L)));
        weight.push_back(double(msm_cube_texel_weight(msm_cube_face_coordinate(i, 0.5f, float(m)),
                                                      msm_cube_face_coordinate(j, 0.5f, float(m)), float(m))));
        energy += luminance.back() * weight.back();
        solid_angle += weight.back();
      }
  // Compensated: the radiance above the probe's mean is what the cosine samples, whose density is
  // smooth, draw poorly; the rest they draw well, and the balance heuristic gives them all of it.
  const double floor = sampling == ProbeSampling::compensated ? energy / solid_angle : 0.0;
  cdf.reserve(texels);
  double total = 0.0;
  for (std::size_t t = 0; t < texels; ++t) {
    total += std::max(luminance[t] - floor, 0.0) * weight[t];
    cdf.push_back(total);
  }
  if (!(total > 0.0)) {
    cdf.clear(); // a uniform or black probe: only the cosine samples
    return;
  }
  for (double& c : cdf) c /= total;
  guide.resize(texels);
  for (std::size_t k = 0, t = 0; k < texels; ++k) {
    const double x = double(k) / double(texels);
    while (t + 1 < texels && !(cdf[t] > x)) ++t;
    guide[k] = std::uint32_t(t);
  }
}

std::size_t EnvironmentLighting::texel_of(double x) const {
  // k = floor(x n) but for the product's rounding: the interval one guide entry wider each side.
  const std::size_t n = guide.size(), k = std::min(std::size_t(x * double(n)), n - 1);
  const auto first = cdf.begin() + guide[k > 0 ? k - 1 : 0];
  const auto last = k + 2 < n ? cdf.begin() + guide[k + 2] + 1 : cdf.end();
  return std::min<std::size_t>(std::upper_bound(first, last, x) - cdf.begin(), n - 1);
}

EnvironmentSample environment_irradiance(const EffectContext& ctx, const EnvironmentLighting& lighting,
                                         const SurfaceHit& hit, const glm::dvec3& n, const glm::dvec3& view, Rng& rng) {
  const int count = ctx.settings.samples;
  const SampleSet set(ctx.settings.sampler, count);
  const glm::dvec3 facing = glm::dot(hit.normal, view) > 0.0 ? -hit.normal : hit.normal;
  const int m = lighting.size;
  const bool probe = !lighting.radiance.empty(), probe_sampled = !lighting.cdf.empty();
  // The plain importance sampling as it is measured against: also without the guide table and
  // with one ray at a time (the same texels and rays; ProbeSampling).
  const bool plain = lighting.sampling == ProbeSampling::luminance;
  const auto probability = [&](std::size_t t) {
    return probe_sampled ? lighting.cdf[t] - (t ? lighting.cdf[t - 1] : 0.0) : 0.0;
  };
  // Solid-angle density of the probe sampler at a point (u, v) of texel t: the texel's
  // probability over its area 4 / m² on the face plane, times the plane's dA / dω.
  const auto probe_pdf = [&](std::size_t t, float u, float v) {
    return probability(t) / double(msm_cube_texel_weight(u, v, float(m)));
  };
  glm::dvec3 tx, ty;
  basis(n, tx, ty);
  // The rays of a batch of samples, traced together (Tracer::occluded's packets): f / pdf of each
  // direction and the sample it belongs to. V(ω) = 0 below the geometric horizon (the ray crosses
  // the surface itself): those directions count in the unoccluded sum only, untraced.
  const std::size_t per_sample = 2 + lighting.cones.size();
  std::vector<glm::dvec3> origins(kSampleBatch * per_sample), dirs(origins.size()), values(origins.size());
  std::vector<int> owners(origins.size());
  const auto blocked = std::make_unique<bool[]>(origins.size());
  std::array<glm::dvec3, kSampleBatch> value, value0;
  EnvironmentSample out;
  RunningStats stats;
  glm::dvec3 sum(0.0), sum0(0.0);
  for (int first = 0; first < count; first += kSampleBatch) {
    const int batch = std::min(kSampleBatch, count - first);
    int rays = 0;
    const auto add = [&](int sample, const glm::dvec3& f, const glm::dvec3& d) {
      value0[sample] += f;
      if (glm::dot(facing, d) <= 0.0) return;
      origins[rays] = offset_origin(hit.p, hit.normal, hit.scale, d);
      dirs[rays] = d;
      values[rays] = f;
      owners[rays++] = sample;
    };
    for (int b = 0; b < batch; ++b) {
      const int i = first + b;
      value[b] = value0[b] = glm::dvec3(0.0);
      if (probe_sampled) {
        // Probe sample: the texel by the first coordinate, the point inside it by what is left of it and the second.
        const glm::dvec2 a = plain ? set.point(i, rng) : set.point_along_first(i, rng);
        const std::size_t t =
            plain ? std::min<std::size_t>(std::upper_bound(lighting.cdf.begin(), lighting.cdf.end(), a.x) -
                                              lighting.cdf.begin(),
                                          lighting.cdf.size() - 1)
                  : lighting.texel_of(a.x);
        const double p = probability(t);
        const double s = p > 0.0 ? std::clamp((a.x - (lighting.cdf[t] - p)) / p, 0.0, 1.0) : 0.5;
        const int face = int(t / (std::size_t(m) * m)), j = int(t / m % m), k = int(t % m);
        const float u = msm_cube_face_coordinate(k, float(s), float(m)),
                    v = msm_cube_face_coordinate(j, float(a.y), float(m));
        const glm::dvec3 d = glm::normalize(glm::dvec3(msm_cube_direction(face, u, v)));
        const double c = glm::dot(n, d);
        if (c > 0.0) add(b, glm::dvec3(lighting.radiance[t]) * (c / (probe_pdf(t, u, v) + c / kPi)), d);
      }
      if (probe) {
        // Cosine sample.
        const glm::dvec2 q2 = concentric_disc(set.point(i, rng));
        const double z = std::sqrt(std::max(0.0, 1.0 - q2.x * q2.x - q2.y * q2.y));
        const glm::dvec3 e = glm::normalize(q2.x * tx + q2.y * ty + z * n);
        const double ce = glm::dot(n, e);
        if (ce > 0.0) {
          const MsmCubeCoord q = msm_cube_coord(glm::vec3(e));
          const int qi = std::clamp(int((q.uv.x + 1.0f) * 0.5f * m), 0, m - 1);
          const int qj = std::clamp(int((q.uv.y + 1.0f) * 0.5f * m), 0, m - 1);
          const std::size_t te = (std::size_t(q.face) * m + qj) * m + qi;
          add(b, glm::dvec3(lighting.radiance[te]) * (ce / (probe_pdf(te, q.uv.x, q.uv.y) + ce / kPi)), e);
        }
      }
      for (const ConeLight& l : lighting.cones) {
        const glm::dvec2 a = set.point(i, rng);
        if (l.rectangle) {
          const glm::dvec3 p = l.axis + (2.0 * a.x - 1.0) * l.half_x * l.x + (2.0 * a.y - 1.0) * l.half_y * l.y;
          const double r = glm::length(p);
          const glm::dvec3 d = p / r;
          const double c = glm::dot(n, d);
          if (c > 0.0) add(b, l.estimate * (c / (r * r * r)), d); // cos θ = 1 / r
          continue;
        }
        const double cos_t = 1.0 - a.x * (1.0 - l.cos_alpha), sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
        const double phi = 2.0 * kPi * a.y;
        const glm::dvec3 d = glm::normalize(cos_t * l.axis + sin_t * (std::cos(phi) * l.x + std::sin(phi) * l.y));
        const double c = glm::dot(n, d);
        if (c > 0.0) add(b, l.estimate * c, d);
      }
    }
    if (plain)
      for (int r = 0; r < rays; ++r) blocked[r] = ctx.tracer.occluded(origins[r], dirs[r]);
    else
      ctx.tracer.occluded(origins.data(), dirs.data(), rays, blocked.get());
    out.rays += std::uint64_t(rays);
    for (int r = 0; r < rays; ++r)
      if (!blocked[r]) value[owners[r]] += values[r];
    for (int b = 0; b < batch; ++b) {
      sum += value[b];
      sum0 += value0[b];
      stats.add(double(msm_luminance(glm::vec3(value[b]))));
    }
  }
  out.irradiance = sum / double(count);
  out.unoccluded = sum0 / double(count);
  out.std_error = stats.std_error();
  out.samples = count;
  return out;
}

} // namespace msm::reference::detail
