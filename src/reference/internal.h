// Internals of msm::reference: the Embree tracer, the per-pixel generator and sample sets, and
// the effects. One effect = one function effect_<name>() in its own file effect_<name>.cpp,
// registered in reference.cpp (effect_function()).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "msm/reference/reference.h"
#include "msm/util/random.h"

namespace msm::reference::detail {

// ---- Random numbers --------------------------------------------------------------------------

// One generator per pixel (msm/util/random.h).
using Rng = util::SplitMix64;

// The generator of pixel (x, y): depends on nothing but these (not on threads or order).
Rng pixel_rng(std::uint64_t seed, int x, int y, Effect effect);

// N points of [0,1)^2 drawn by a Sampler (see reference.h): point(i) for i = 0..N-1, each call
// consuming random numbers from the pixel's generator.
class SampleSet {
 public:
  SampleSet(Sampler sampler, int count);
  int count() const { return count_; }
  glm::dvec2 point(int i, Rng& rng) const {
    const double a = rng.uniform(), b = rng.uniform();
    if (i < grid_ * grid_) {
      // Jittered cell (i mod m, i div m) of the m x m grid. The row without an integer division
      // (the slowest instruction per sample): (i + 0.5) / m is at least 0.5 / m from an integer and
      // its rounding error below m · 2^-52, so the floor is exact for m < 2^25.
      const double inv = inverse_grid_;
      const int row = int((i + 0.5) * inv), column = i - row * grid_;
      constexpr double below_one = 1.0 - 0x1.0p-53; // std::nextafter(1.0, 0.0)
      return {std::min((column + a) * inv, below_one), std::min((row + b) * inv, below_one)};
    }
    return {a, b};
  }
  // The i-th of N points with the first coordinate stratified over all N (jittered in [i, i + 1) /
  // N) and the second independent: for a first coordinate that matters most (the environment's
  // texel choice), N strata where point() has m. The independent sampler: independent points.
  glm::dvec2 point_along_first(int i, Rng& rng) const {
    const double a = rng.uniform(), b = rng.uniform();
    constexpr double below_one = 1.0 - 0x1.0p-53;
    return sampler_ == Sampler::stratified ? glm::dvec2(std::min((i + a) / count_, below_one), b) : glm::dvec2(a, b);
  }

 private:
  Sampler sampler_;
  int count_, grid_;
  double inverse_grid_ = 0.0; // 1 / grid_
};

// Samples whose rays an effect generates before it traces them (on the stack): the arithmetic of
// one sample is a chain of dependent steps, which the processor overlaps across a batch, but not
// across the tracer's calls.
inline constexpr int kSampleBatch = 32;

// Shirley-Chiu concentric map of [0,1)^2 onto the unit disc (area-preserving, keeps strata), in
// double or single precision (T = double or float).
template <class T>
inline glm::vec<2, T> concentric_disc(glm::vec<2, T> u) {
  const T a = T(2) * u.x - T(1), b = T(2) * u.y - T(1);
  // Shirley-Chiu: r = a, φ = π/4 · b/a where |a| > |b|; else r = b, φ = π/2 − π/4 · a/b, whose
  // cosine and sine are the sine and cosine of x = π/4 · a/b. So one angle x, |x| <= π/4, and
  // selects, not branches (which way a sample goes is random; and a loop of them vectorizes), and
  // no libm call: sin and cos of x by their Taylor series, nested (Horner); in double to x^15 and
  // x^16 (the first terms left out are below 5e-17 and 3e-18, under half an ulp of the results),
  // in float to x^9 and x^10 (below 1.7e-9 and 1.2e-10, under half a float ulp). a = b = 0 (r = 0)
  // gives x = 0 and the centre.
  const bool wide = std::abs(a) > std::abs(b);
  const T r = wide ? a : b, q = wide ? b : a;
  const T den = r + T(r == T(0)); // r, or 1 where r = 0 (no branch around the division)
  const T x = T(std::numbers::pi / 4.0) * (q / den), x2 = x * x;
  static constexpr int terms = std::is_same_v<T, float> ? 5 : 8;
  T s = T(1), c = T(1);
  // for k = terms, ..., 1 (unrolled: a loop inside a batch's loop would keep it from vectorizing)
  [&]<int... K>(std::integer_sequence<int, K...>) {
    constexpr auto step = [](int k, T x2, T& s, T& c) {
      c = T(1) - x2 * T(1.0 / ((2 * k - 1) * (2 * k))) * c;
      if (k < terms) s = T(1) - x2 * T(1.0 / ((2 * k) * (2 * k + 1))) * s;
    };
    (step(terms - K, x2, s, c), ...);
  }
  (std::make_integer_sequence<int, terms>{});
  s *= x;
  const T rc = r * c, rs = r * s;
  return {wide ? rc : rs, wide ? rs : rc};
}

// Running mean and unbiased variance (Welford).
struct RunningStats {
  int n = 0;
  double mean = 0.0, m2 = 0.0;
  void add(double v) {
    ++n;
    const double d = v - mean;
    mean += d / n;
    m2 += d * (v - mean);
  }
  double std_error() const { return n > 1 ? std::sqrt(std::max(0.0, m2 / (n - 1)) / n) : 0.0; }
};

// ---- Tracer ----------------------------------------------------------------------------------

// The visible surface at a primary (or continuation) ray's hit.
struct SurfaceHit {
  glm::dvec3 p{0.0};      // on the plane of the hit triangle, on the ray
  glm::dvec3 normal{0.0}; // unit geometric normal of the triangle (counter-clockwise front)
  double scale = 1.0;     // max(|p|_inf, |vertex coordinates|_inf of the triangle)
  std::uint32_t object = 0, triangle = 0;
  float u = 0.0f, v = 0.0f; // Embree barycentrics (of vertices 1 and 2)
  glm::dvec3 incoming{0.0}; // unit direction of the ray that found it
};

// Offset of a shadow-ray origin: eps = kOffsetScale * scale along the normal's side facing `towards`.
inline glm::dvec3 offset_origin(const glm::dvec3& p, const glm::dvec3& normal, double scale,
                                const glm::dvec3& towards) {
  const double side = glm::dot(normal, towards) >= 0.0 ? 1.0 : -1.0;
  return p + (side * kOffsetScale * scale) * normal;
}
inline double point_scale(const glm::dvec3& p) { return std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}); }

class Tracer {
 public:
  explicit Tracer(const scene::Scene& scene); // builds the Embree scene; throws on failure
  ~Tracer();
  Tracer(const Tracer&) = delete;
  Tracer& operator=(const Tracer&) = delete;

  const scene::Scene& scene() const { return scene_; }

  // Closest hit of origin + t dir, t in [0, tfar] (dir unit); false if none.
  bool closest(const glm::dvec3& origin, const glm::dvec3& dir, double tfar, SurfaceHit& hit) const;
  // True if anything lies on origin + t dir, t in [0, inf).
  bool occluded(const glm::dvec3& origin, const glm::dvec3& dir) const;
  // True if anything lies on origin + t dir, t in [0, tfar]: a ray to a light at distance tfar.
  bool occluded(const glm::dvec3& origin, const glm::dvec3& dir, double tfar) const;
  // occluded() of n rays, as packets of 8 (a pixel's sample rays are nearly coherent).
  void occluded(const glm::dvec3* origins, const glm::dvec3* dirs, int n, bool* blocked) const;
  // occluded() of n rays from one origin, their directions in single precision (what Embree
  // traces) as three arrays of components: a soft light's rays (packets as above).
  void occluded(const glm::dvec3& origin, const float* dir_x, const float* dir_y, const float* dir_z, int n,
                bool* blocked) const;

  struct Transmission {
    glm::dvec3 channels{1.0};   // per RGB channel
    double transmittance = 1.0; // the mean of the three channels (exactly channels.r when all equal)
    int crossings = 0;
    std::uint64_t rays = 0;
  };
  // Per channel c, the product of (1 - alpha * (1 - transmission_color_c)) (the material's
  // channel_opacity, in double precision) over the surfaces crossed by origin + t dir, t >= 0,
  // counting at most max_crossings of them; stops early when every channel is 0. alpha = the
  // material's constant times its opacity texture or noise (scene::opacity_image) at the hit's
  // uv. Without transmission colours every channel is the product of (1 - alpha).
  // Surfaces at t > tfar (beyond a light) do not count.
  Transmission transmission(const glm::dvec3& origin, const glm::dvec3& dir, int max_crossings,
                            double tfar = std::numeric_limits<double>::infinity()) const;

  // Interpolated vertex normal at a hit (unit).
  glm::dvec3 shading_normal(const SurfaceHit& hit) const;
  const scene::Material& material(const SurfaceHit& hit) const;
  // The opacity alpha at a hit (constant times texture or noise); 1 for alpha-tested materials
  // (their hits are where the surface exists).
  double opacity(const SurfaceHit& hit) const;
  // The albedo at a hit: the material's constant times its texture (decoded from sRGB to linear,
  // then bilinear with repeat: what the renderer's sRGB texture with a linear sampler gives).
  glm::vec3 albedo(const SurfaceHit& hit) const;
  // Whether an alpha-tested object exists at barycentrics (u, v) of a triangle: opacity >= the
  // material's alpha_cutoff (always true for other materials). Hits where it does not are
  // skipped by every query (Embree filter functions).
  bool solid(std::uint32_t object, std::uint32_t triangle, float u, float v) const;

  struct Impl; // Embree device and scene

 private:
  glm::vec2 uv(std::uint32_t object, std::uint32_t triangle, float u, float v) const;
  double texture_opacity(std::uint32_t object, std::uint32_t triangle, float u, float v) const;

  struct LinearImage { // an albedo texture in linear RGB
    int width = 0, height = 0;
    std::vector<glm::vec3> texels;
  };
  const scene::Scene& scene_;
  std::vector<scene::OpacityImage> opacity_images_; // per material (width 0: none)
  std::vector<LinearImage> albedo_images_;          // per material (width 0: none)
  std::unique_ptr<Impl> impl_;
};

// ---- Effects ---------------------------------------------------------------------------------

// Everything an effect needs, computed once per render.
struct EffectContext {
  const Tracer& tracer;
  const Settings& settings;
  LightFrame frame;
  glm::dvec3 towards_light{0.0};
  // filtered
  FilterKernel kernel;
  glm::dvec3 texel_x{0.0}, texel_y{0.0}; // world vector of one texel along light-space x / y
  // soft: the light's shape (traced_light) and half-sizes in the plane at unit distance along
  // towards_light (tangents of the half-angles); the disc uses half_x as its radius.
  LightShape light_shape = LightShape::disc;
  double half_x = 0.0, half_y = 0.0;
  glm::dvec3 light_x{0.0}, light_y{0.0}; // unit, orthogonal to towards_light
};

struct EffectResult {
  double value = 1.0;            // visibility or transmittance (translucent: the mean of rgb)
  std::optional<glm::dvec3> rgb; // translucent only: transmittance per RGB channel
  // soft only: the light's cosine-weighted visibility that replaces max(n·L, 0) V in the radiance
  // (reference.h, effect soft)
  std::optional<double> lit;
  double std_error = 0.0;
  int samples = 1;
  std::uint64_t rays = 0; // shadow rays traced
};

// The result of a Monte Carlo effect with one shadow ray per sample.
inline EffectResult monte_carlo_result(const RunningStats& stats) {
  EffectResult r;
  r.value = stats.mean;
  r.std_error = stats.std_error();
  r.samples = stats.n;
  r.rays = std::uint64_t(stats.n);
  return r;
}
// The statistics of n samples of which `ones` are 1 and the rest 0 (visible or not): what
// RunningStats gives for them up to rounding (mean k / n, sum of squared deviations k (n − k) / n),
// without its division per sample.
struct BinaryStats {
  int n = 0, ones = 0;
};
inline EffectResult monte_carlo_result(const BinaryStats& stats) {
  RunningStats sums;
  sums.n = stats.n;
  if (stats.n > 0) {
    const double n = stats.n, k = stats.ones;
    sums.mean = k / n;
    sums.m2 = k * (n - k) / n;
  }
  return monte_carlo_result(sums);
}

using EffectFunction = EffectResult (*)(const EffectContext&, const SurfaceHit&, Rng&);

EffectResult effect_hard(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng);
EffectResult effect_filtered(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng);
EffectResult effect_soft(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng);
// filtered for a spot or point light (reference.h's definition in the light's own map), at a
// receiver whose shading normal faces the light.
EffectResult filtered_local_visibility(const EffectContext& ctx, const SurfaceHit& hit, const scene::LocalLight& light,
                                       Rng& rng);
EffectResult effect_translucent(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng);

// scattering (effect_scattering.cpp): the transmittance-weighted visible fraction of each light
// along camera + t dir, t in [0, s] (dir unit), from ctx.settings.samples distances t with one
// shadow ray per light each; `visible` combines the lights with the weights w_l
// (msm_scattering_light_weight; all 0: 1), and its std_error is that of the combined samples
// Σ w_l V_l(t) / Σ w_l. With one light, visible is that light's.
// A spot or point light (local): its in-scattering f E (msm_local_light_inscattering) varies along
// the ray; its shadow rays end at the light. Its weight at t is the luminance of f E there, its
// visible fraction Σ lum(f E) V / Σ lum(f E) over the samples, and light_unshadowed the samples'
// mean of f E (rgb): the light's in-scattering is then visible × light_unshadowed × ∫₀ˢ exp(−σt t) dt.
struct ScatteringLight {
  glm::dvec3 towards_light{0.0, 1.0, 0.0}; // unit (directional)
  double weight = 1.0;                     // w_l (directional)
  const scene::LocalLight* local = nullptr;
};
struct ScatteringSample {
  double visible = 1.0, std_error = 0.0;
  std::vector<double> light_visible;        // per light
  std::vector<glm::dvec3> light_unshadowed; // per light: a local light's mean f E (directional: 0)
  int samples = 0;
  std::uint64_t rays = 0;
};
ScatteringSample scattering_along_ray(const EffectContext& ctx, const scene::Medium& medium, const glm::dvec3& camera,
                                      const glm::dvec3& dir, double s, std::span<const ScatteringLight> lights,
                                      Rng& rng);

// Every light of a scene with spot or point lights (effect_lights.cpp), for the hard and soft
// effects. A directional light's shadow rays run to infinity, a spot or point light's to the light
// (a light inside a closed mesh reaches nothing outside it). hard: one ray per light towards its
// centre. soft: `samples` directions per light of some extent, uniform in the cone it fills (a
// directional light's angular_extent_deg as a disc; a spot or point light's sphere of `radius`,
// sin α = r / d), each ray ending on the sphere; lights without extent get one ray. translucent:
// one ray per light, V the transmittance per channel (Tracer::transmission up to the light).
// lit_l = ∫ max(n·ω, 0) V dω / (π sin² α) over the cone (max(n·l, 0) V for a point), the
// light's unoccluded lit0_l from the same samples.
struct LightsSample {
  glm::dvec3 direct{0.0};      // Σ_l msm_direct_light(E_l, lit_l, 1)
  double visible = 0.0;        // Σ_l lum(E_l) lit_l / Σ_l lum(E_l) lit0_l; 0 where no light arrives
  glm::dvec3 visible_rgb{0.0}; // the same per channel (translucent; else all equal to visible)
  double std_error = 0.0;      // of visible, from the per-sample values (soft)
  double n_dot_l = 0.0;        // with the first light's centre (directional lights first, then spot and point)
  int samples = 1;
  std::uint64_t rays = 0;
};
// n: the shading normal turned towards the viewer.
LightsSample trace_lights(const EffectContext& ctx, const SurfaceHit& hit, const glm::dvec3& n, Rng& rng);

// environment (effect_environment.cpp): the lights of a scene's image-based lighting, built once
// per render. Throws std::invalid_argument for a scene without a "probe".
// A light of the environment effect: a uniform cone (a disc light), or a rectangle (x, y: the
// light frame's axes, as the renderer's shadow map has them) sampled uniformly on its plane at
// unit distance: a sample of direction d stands for area / cos³ θ of solid angle (θ off the axis).
struct ConeLight {
  glm::dvec3 axis{0.0, 1.0, 0.0}, x{1.0, 0.0, 0.0}, y{0.0, 0.0, 1.0}; // orthonormal, axis towards the light
  double cos_alpha = 1.0;                                             // of the half-angle (cone)
  bool rectangle = false;
  double half_x = 0.0, half_y = 0.0; // rectangle: tangents of the half extents along x, y
  // cone: irradiance on a facing surface x 2 / (1 + cos α), f / pdf of a uniform cone sample;
  // rectangle: that irradiance x area / F (msm_rect_light_facing_integral), times cos³ θ per sample.
  glm::dvec3 estimate{0.0};
};
// How the environment effect draws its probe samples (reference.h, "environment"). `compensated`
// (the default): texels in proportion to max(Y − Ȳ, 0) x solid angle, Ȳ the probe's mean luminance
// (Karlík et al., "MIS Compensation", 2019; pbrt-v4's image infinite light), the texel choice
// stratified over all N samples (SampleSet::point_along_first). `luminance`: texels in proportion
// to Y x solid angle, the choice stratified by the jittered grid's columns (SampleSet::point): the
// plain importance sampling that the compensated one is measured against. Process-wide: a
// measurement (bench/environment_noise.cpp) compares the two in one binary.
enum class ProbeSampling { compensated, luminance };
void set_probe_sampling(ProbeSampling sampling);
ProbeSampling probe_sampling();

struct EnvironmentLighting {
  EnvironmentLighting(const scene::Scene& scene, bool probe_lights);
  int size = 0;                    // of the probe's faces; 0 with probe_lights (no probe sampled)
  std::vector<glm::vec3> radiance; // 6 size² texels, face-major, rows along +v
  ProbeSampling sampling = ProbeSampling::compensated;
  std::vector<double> cdf; // of the sampling's distribution, normalized, cdf.back() = 1; empty: no probe samples
  // guide[k] = the first texel t with cdf[t] > k / guide.size(): the texel of x in [k, k + 1) /
  // guide.size() lies in [guide[k], guide[k + 1]] (a guide table, Chen and Asau 1974).
  std::vector<std::uint32_t> guide;
  std::size_t texel_of(double x) const; // the first t with cdf[t] > x (the last where none is)
  std::vector<ConeLight> cones;         // lights sampled as uniform cones or rectangles
};
struct EnvironmentSample {
  glm::dvec3 irradiance{0.0}, unoccluded{0.0};
  double std_error = 0.0; // of the irradiance's luminance
  int samples = 0;
  std::uint64_t rays = 0;
};
// n: the shading normal turned towards the viewer; view: the primary ray's direction.
EnvironmentSample environment_irradiance(const EffectContext& ctx, const EnvironmentLighting& lighting,
                                         const SurfaceHit& hit, const glm::dvec3& n, const glm::dvec3& view, Rng& rng);

} // namespace msm::reference::detail
