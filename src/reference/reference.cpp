// msm::reference: settings, the camera, the per-pixel loop (TBB) and the output images.
#include "msm/reference/reference.h"
#include "msm/reference/settings_schema.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "internal.h"
#include "msm/light_probe.h"
#include "msm/probe/probe.h"
#include "msm/scattering.h"
#include "msm/shading.h"
#include "msm/util/clock.h"
#include "msm/util/limits.h"

namespace msm::reference {

// ---- Names -------------------------------------------------------------------------------------

std::string_view to_string(Effect effect) {
  switch (effect) {
  case Effect::hard: return "hard";
  case Effect::filtered: return "filtered";
  case Effect::soft: return "soft";
  case Effect::translucent: return "translucent";
  case Effect::scattering: return "scattering";
  case Effect::environment: return "environment";
  }
  return "?";
}

std::optional<Effect> parse_effect(std::string_view name) {
  for (Effect e : kEffects)
    if (to_string(e) == name) return e;
  return std::nullopt;
}

bool is_monte_carlo(Effect effect) {
  return effect == Effect::filtered || effect == Effect::soft || effect == Effect::scattering ||
         effect == Effect::environment;
}

std::string_view to_string(LightShape shape) { return shape == LightShape::disc ? "disc" : "rectangle"; }

std::optional<LightShape> parse_light_shape(std::string_view name) {
  if (name == "disc") return LightShape::disc;
  if (name == "rectangle") return LightShape::rectangle;
  return std::nullopt;
}

std::string_view to_string(Sampler sampler) { return sampler == Sampler::stratified ? "stratified" : "independent"; }

std::optional<Sampler> parse_sampler(std::string_view name) {
  if (name == "stratified") return Sampler::stratified;
  if (name == "independent") return Sampler::independent;
  return std::nullopt;
}

// ---- Settings ----------------------------------------------------------------------------------

void validate(const Settings& s) {
  // Each setting in its declared range or choices (msm/reference/settings_schema.h): the ranges
  // are stated there only.
  for (const SettingDeclaration& setting : setting_declarations()) try {
      check_setting(setting, setting.get(s));
    } catch (const SettingError& e) { throw std::invalid_argument(fmt::format("{}: {}", setting.key, e.what())); }
  if (s.threads < 0 || s.threads > kMaxThreads)
    throw std::invalid_argument(fmt::format("threads {} is out of range [0, {}]", s.threads, kMaxThreads));
  // What a range cannot say: an odd filter size, a light width or height of a disc.
  [[maybe_unused]] const FilterKernel kernel(s.filter_size, s.filter_sigma);
  if (s.light_shape == LightShape::disc && (s.light_width_deg || s.light_height_deg))
    throw std::invalid_argument("a light width or height applies to a rectangular light only, not a disc");
}

TracedLight traced_light(const scene::DirectionalLight& light, const Settings& s) {
  const auto as_float = [](const std::optional<double>& deg) -> std::optional<float> {
    if (deg) return float(*deg);
    return std::nullopt;
  };
  const scene::DirectionalLight drawn =
      scene::overridden_light(light, as_float(s.light_extent_deg), as_float(s.light_height_deg));
  TracedLight t;
  t.extent_deg = drawn.angular_extent_deg;
  t.shape = s.light_shape.value_or(drawn.rectangular() || s.light_width_deg ? LightShape::rectangle : LightShape::disc);
  if (t.shape == LightShape::disc) {
    t.width_deg = t.height_deg = t.extent_deg;
  } else {
    t.width_deg = s.light_width_deg.value_or(t.extent_deg);
    t.height_deg = drawn.angular_height_deg.value_or(t.extent_deg);
  }
  return t;
}

std::uint64_t estimated_bytes(const Settings& s, std::uint64_t triangles) {
  // environment keeps a 4-channel irradiance image, as scattering keeps its scattering image.
  const std::uint64_t per_pixel = s.effect == Effect::translucent ? limits::kTracerBytesPerPixelTranslucent
                                  : s.effect == Effect::scattering || s.effect == Effect::environment
                                      ? limits::kTracerBytesPerPixelScattering
                                      : limits::kTracerBytesPerPixel;
  return triangles * limits::kTracerBytesPerTriangle + std::uint64_t(s.width) * std::uint64_t(s.height) * per_pixel;
}

void check_limits(const Settings& s, std::uint64_t triangles) {
  limits::check_triangles(triangles);
  limits::check_bytes(fmt::format("a {}x{} {} reference of {} triangles", s.width, s.height, to_string(s.effect),
                                  limits::with_commas(triangles)),
                      estimated_bytes(s, triangles));
}

// ---- Rendering ---------------------------------------------------------------------------------

namespace {

using namespace detail;

EffectFunction effect_function(Effect effect) {
  switch (effect) {
  case Effect::hard: return effect_hard;
  case Effect::filtered: return effect_filtered;
  case Effect::soft: return effect_soft;
  case Effect::translucent: return effect_translucent;
  case Effect::scattering: return effect_hard;  // the surface's own shadow; the ray's is added apart
  case Effect::environment: return effect_hard; // unused: environment_irradiance() shades apart
  }
  throw std::invalid_argument("unknown effect");
}

Result render_in_arena(const scene::Scene& scene, const Settings& settings);

} // namespace

Result render(const scene::Scene& scene, const Settings& settings) {
  validate(settings);
  check_limits(settings, scene.triangle_count());
  if (settings.threads == 0) return render_in_arena(scene, settings);
  tbb::task_arena arena(settings.threads);
  return arena.execute([&] { return render_in_arena(scene, settings); });
}

namespace {

// The scene's first directional light; a default one where it has only spot and point lights.
scene::DirectionalLight first_light(const scene::Scene& scene) {
  return scene.lights.empty() ? scene::DirectionalLight{} : scene.light();
}

// Spot and point lights are traced by the hard, filtered, soft and translucent effects (trace_lights) and
// the scattering effect (their in-scattering along the view rays, the surfaces' hard shadows), as
// the scene declares them; std::invalid_argument for what else a scene with them asks.
void check_local_lights(const scene::Scene& scene, const Settings& settings) {
  if (scene.local_lights.empty()) return;
  if (settings.effect != Effect::hard && settings.effect != Effect::soft && settings.effect != Effect::translucent &&
      settings.effect != Effect::scattering && settings.effect != Effect::filtered)
    throw std::invalid_argument(fmt::format("the {} effect traces directional lights only; a scene with spot or point "
                                            "lights is traced by the hard, filtered, soft, translucent and scattering "
                                            "effects",
                                            to_string(settings.effect)));
  // The filtered effect's directional map is the first directional light's frame (Scene::light_frame).
  if (settings.effect == Effect::filtered && scene.lights.size() > 1)
    throw std::invalid_argument("the filtered effect traces a scene with spot or point lights with at most one "
                                "directional light");
  if (settings.light_extent_deg || settings.light_shape || settings.light_width_deg || settings.light_height_deg)
    throw std::invalid_argument("the light overrides (extent, shape, width, height) change a scene's one directional "
                                "light; a scene with spot or point lights is traced as it declares its lights");
  if (settings.effect == Effect::soft)
    for (const scene::DirectionalLight& l : scene.lights)
      if (l.rectangular() || !l.sub_lights.empty())
        throw std::invalid_argument("the soft effect traces a scene with spot or point lights with disc-shaped "
                                    "directional lights only (no rectangles, no probe lights)");
}

// The light as the soft effect traces it; std::invalid_argument for an extent outside [0, 90) degrees.
// A scene of spot and point lights only has no directional light: a default one stands for it.
TracedLight checked_light(const scene::Scene& scene, const Settings& settings) {
  const TracedLight light = traced_light(first_light(scene), settings);
  if (!(std::isfinite(light.extent_deg) && light.extent_deg >= 0.0 && light.extent_deg < 90.0))
    throw std::invalid_argument(fmt::format("light extent {} degrees is out of range [0, 90)", light.extent_deg));
  return light;
}

// The effects' context: the light frame, one shadow-map texel in world units, and the soft light's
// shape, half-sizes and axes (the light-space axes, made exactly orthonormal to towards_light).
EffectContext effect_context(const Tracer& tracer, const scene::Scene& scene, const Settings& settings,
                             const TracedLight& light) {
  EffectContext ctx{tracer,
                    settings,
                    scene.lights.empty() ? LightFrame{} : scene.light_frame(),
                    {},
                    FilterKernel(settings.filter_size, settings.filter_sigma)};
  ctx.towards_light = ctx.frame.towards_light;
  ctx.texel_x = ctx.frame.x_axis * (ctx.frame.extent.x / settings.shadow_size);
  ctx.texel_y = ctx.frame.y_axis * (ctx.frame.extent.y / settings.shadow_size);
  ctx.light_x = glm::normalize(ctx.frame.x_axis - glm::dot(ctx.frame.x_axis, ctx.towards_light) * ctx.towards_light);
  ctx.light_y = glm::cross(ctx.towards_light, ctx.light_x);
  if (glm::dot(ctx.light_y, ctx.frame.y_axis) < 0.0) ctx.light_y = -ctx.light_y;
  const auto half_tan = [](double deg) { return std::tan(deg * std::numbers::pi / 360.0); };
  ctx.light_shape = light.shape;
  ctx.half_x = half_tan(light.width_deg);
  ctx.half_y = half_tan(light.height_deg);
  return ctx;
}

// The result's images for the effect, every pixel at its starting value.
void create_images(Result& result, const Settings& settings) {
  const int W = settings.width, H = settings.height;
  const bool mc = is_monte_carlo(settings.effect);
  std::vector<std::string> names{"visibility", "background"};
  if (mc) names.insert(names.end(), {"sample_count", "std_error"});
  result.visibility = image::Image(W, H, names);
  // translucent: the transmittance per RGB channel (coloured shadows; "visibility" is their
  // mean), in an image of its own (an image has at most 4 channels).
  if (settings.effect == Effect::translucent)
    result.visibility_rgb = image::Image(W, H, {"visibility_r", "visibility_g", "visibility_b"}, 1.0f);
  result.radiance = image::Image(W, H, 3);
  result.surface = image::Image(W, H, {"n_dot_l", "object"});
  if (settings.effect == Effect::scattering) result.scattering = image::Image(W, H, {"R", "G", "B", "length"});
  if (settings.effect == Effect::environment) result.irradiance = image::Image(W, H, {"R", "G", "B", "std_error"});
  for (std::size_t i = 0; i < result.surface.pixel_count(); ++i) result.surface.pixels()[2 * i + 1] = -1.0f;
  result.samples = mc ? settings.samples : 1;
}

// A probe-lit scene's probe as the renderer loads it (GpuScene); an empty cube map without one.
msm::probe::CubeMap background_probe(const scene::Scene& scene) {
  if (!scene.probe) return {};
  try {
    return msm::probe::load_probe(scene.probe->file.string(), scene.probe->size, scene.probe->rotation_deg,
                                  scene.probe->intensity);
  } catch (const msm::probe::ProbeError& e) { throw std::invalid_argument(e.what()); }
}

// The per-pixel work of one render: the camera ray of a pixel to its visible surface, the effect
// there, and what it writes into the result's images. Rows may be traced concurrently: each writes
// only its own pixels and its own entries of row_sum and row_background.
class PixelTracer {
 public:
  PixelTracer(const scene::Scene& scene, const Settings& settings, const EffectContext& ctx,
              const EnvironmentLighting* lighting, Result& result)
      : scene_(scene), settings_(settings), ctx_(ctx), tracer_(ctx.tracer), lighting_(lighting), result_(result),
        W_(settings.width), H_(settings.height), mc_(is_monte_carlo(settings.effect)),
        scattering_(settings.effect == Effect::scattering), effect_(effect_function(settings.effect)),
        inv_vp_(glm::inverse(glm::dmat4(scene.camera_view_projection(float(W_) / float(H_))))),
        irradiance_(first_light(scene).irradiance), camera_(scene.camera.position), probe_(background_probe(scene)),
        row_sum(std::size_t(settings.height), 0.0), row_background(std::size_t(settings.height), 0) {
    // scattering: every light of the scene (the first is ctx's), its direction and irradiance.
    if (scattering_)
      for (std::size_t l = 0; l < scene.lights.size(); ++l) {
        light_towards_.push_back(l == 0 ? ctx.towards_light : scene.light_frame(l).towards_light);
        light_irradiance_.emplace_back(scene.lights[l].irradiance);
      }
  }

  // Row y; returns the rays traced.
  std::uint64_t trace_row(int y) {
    std::uint64_t rays = 0;
    for (int x = 0; x < W_; ++x) trace_pixel(x, y, rays);
    return rays;
  }

 private:
  std::size_t pixel(int x, int y) const { return std::size_t(y) * W_ + x; }

  // Camera: unproject NDC depth 0 and 1 with the inverse of the rasterizer's matrix.
  glm::dvec3 unproject(double nx, double ny, double depth) const {
    const glm::dvec4 q = inv_vp_ * glm::dvec4(nx, ny, depth, 1.0);
    return glm::dvec3(q) / q.w;
  }

  glm::vec3 background(const glm::dvec3& dir) const {
    if (!probe_.size) return glm::vec3(0.0f);
    const glm::ivec3 t = msm_cube_texel(glm::vec3(dir), probe_.size);
    return probe_.at(t.z, t.x, t.y);
  }

  // The closest surface along the ray that is not looked through: translucent surfaces (opacity
  // < 1) are, as the renderer's shadow buffer does, and so are the back faces of single-sided
  // materials, which the rasterizer culls.
  bool visible_surface(const glm::dvec3& near, const glm::dvec3& dir, double length, SurfaceHit& hit,
                       std::uint64_t& rays) const {
    ++rays;
    bool found = tracer_.closest(near, dir, length, hit);
    const auto hidden = [&](const SurfaceHit& h) {
      const scene::Material& m = tracer_.material(h);
      return m.translucent() || (!m.double_sided && glm::dot(h.normal, dir) > 0.0);
    };
    for (int crossed = 0; found && hidden(hit) && crossed < kMaxCrossings; ++crossed) {
      const glm::dvec3 beyond = offset_origin(hit.p, hit.normal, hit.scale, dir);
      found = tracer_.closest(beyond, dir, length - glm::length(beyond - near), hit);
      ++rays;
    }
    return found;
  }

  void trace_pixel(int x, int y, std::uint64_t& rays) {
    const double nx = (x + 0.5) / W_ * 2.0 - 1.0, ny = (y + 0.5) / H_ * 2.0 - 1.0;
    const glm::dvec3 near = unproject(nx, ny, 0.0), far = unproject(nx, ny, 1.0);
    const double length = glm::length(far - near);
    const glm::dvec3 dir = (far - near) / length;
    float* v = result_.visibility.pixels().data() + pixel(x, y) * result_.visibility.channels();
    SurfaceHit hit;
    if (!visible_surface(near, dir, length, hit, rays)) {
      v[0] = 1.0f;
      v[1] = 1.0f;
      ++row_background[y];
      const glm::vec3 sky = background(dir);
      write_radiance(x, y, sky);
      if (scattering_) add_scattering(x, y, dir, far, sky, rays);
      return; // sample_count and std_error 0 (scattering: the ray's)
    }
    Rng rng = pixel_rng(settings_.seed, x, y, settings_.effect);
    // Shading: interpolated normal turned towards the viewer.
    glm::dvec3 n = tracer_.shading_normal(hit);
    if (glm::dot(hit.normal, dir) > 0.0) n = -n;
    if (!scene_.local_lights.empty())
      shade_lights(x, y, hit, n, dir, rng, rays);
    else if (lighting_)
      shade_environment(x, y, hit, n, dir, rng, rays);
    else
      shade_effect(x, y, hit, n, dir, rng, rays);
  }

  // Spot and point lights (with the directional ones): every light of the scene (trace_lights).
  void shade_lights(int x, int y, const SurfaceHit& hit, const glm::dvec3& n, const glm::dvec3& dir, Rng& rng,
                    std::uint64_t& rays) {
    const LightsSample e = trace_lights(ctx_, hit, n, rng);
    rays += e.rays;
    float* v = result_.visibility.pixels().data() + pixel(x, y) * result_.visibility.channels();
    v[0] = float(e.visible);
    if (mc_) {
      v[2] = float(e.samples);
      v[3] = float(e.std_error);
    }
    if (!scattering_) row_sum[y] += e.visible;
    if (!result_.visibility_rgb.empty()) {
      float* t = result_.visibility_rgb.pixels().data() + pixel(x, y) * 3;
      t[0] = float(e.visible_rgb.r), t[1] = float(e.visible_rgb.g), t[2] = float(e.visible_rgb.b);
    }
    write_surface(x, y, float(e.n_dot_l), hit);
    const glm::vec3 colour = msm_surface_radiance(tracer_.albedo(hit), glm::vec3(e.direct), MSM_AMBIENT);
    write_radiance(x, y, colour);
    if (scattering_) add_scattering(x, y, dir, hit.p, colour, rays);
  }

  void write_radiance(int x, int y, const glm::vec3& colour) {
    float* c = result_.radiance.pixels().data() + pixel(x, y) * 3;
    c[0] = colour.r, c[1] = colour.g, c[2] = colour.b;
  }

  void write_surface(int x, int y, float n_dot_l, const SurfaceHit& hit) {
    float* q = result_.surface.pixels().data() + pixel(x, y) * 2;
    q[0] = n_dot_l;
    q[1] = float(hit.object);
  }

  // environment: the probe's irradiance through the scene's occluders against the unoccluded one.
  void shade_environment(int x, int y, const SurfaceHit& hit, const glm::dvec3& n, const glm::dvec3& dir, Rng& rng,
                         std::uint64_t& rays) {
    const EnvironmentSample e = environment_irradiance(ctx_, *lighting_, hit, n, dir, rng);
    rays += e.rays;
    const double lum0 = msm_luminance(glm::vec3(e.unoccluded));
    const double visible = lum0 > 0.0 ? msm_luminance(glm::vec3(e.irradiance)) / lum0 : 0.0;
    float* v = result_.visibility.pixels().data() + pixel(x, y) * result_.visibility.channels();
    v[0] = float(visible);
    v[2] = float(e.samples);
    v[3] = float(lum0 > 0.0 ? e.std_error / lum0 : 0.0);
    row_sum[y] += visible;
    const glm::vec3 direct = msm_direct_light(glm::vec3(e.irradiance), 1.0f, glm::vec3(1.0f));
    write_surface(x, y, float(glm::dot(n, ctx_.towards_light)), hit);
    write_radiance(x, y, msm_surface_radiance(tracer_.albedo(hit), direct, MSM_AMBIENT));
    float* ir = result_.irradiance.pixels().data() + pixel(x, y) * 4;
    ir[0] = float(e.irradiance.r), ir[1] = float(e.irradiance.g), ir[2] = float(e.irradiance.b);
    ir[3] = float(e.std_error);
  }

  // Every other effect: the first light's visibility (per channel where the effect gives one), and
  // the surface's radiance.
  void shade_effect(int x, int y, const SurfaceHit& hit, const glm::dvec3& n, const glm::dvec3& dir, Rng& rng,
                    std::uint64_t& rays) {
    const EffectResult e = effect_(ctx_, hit, rng);
    rays += e.rays;
    float* v = result_.visibility.pixels().data() + pixel(x, y) * result_.visibility.channels();
    v[0] = float(e.value);
    if (mc_) {
      v[2] = float(e.samples);
      v[3] = float(e.std_error);
    }
    const glm::vec3 rgb = e.rgb ? glm::vec3(*e.rgb) : glm::vec3(float(e.value));
    if (settings_.effect == Effect::translucent) {
      float* t = result_.visibility_rgb.pixels().data() + pixel(x, y) * 3;
      t[0] = rgb.r;
      t[1] = rgb.g;
      t[2] = rgb.b;
    }
    if (!scattering_) row_sum[y] += e.value;
    const float n_dot_l = float(glm::dot(n, ctx_.towards_light));
    glm::vec3 direct = e.lit ? msm_direct_light(glm::vec3(irradiance_), float(*e.lit), glm::vec3(1.0f))
                             : msm_direct_light(glm::vec3(irradiance_), n_dot_l, rgb);
    // scattering: the surface lit by every light, each with its exact (hard) shadow, as the
    // renderer shades it (msm/shading.h's sum over the lights); the first light's is e.
    for (std::size_t l = 1; scattering_ && l < light_towards_.size(); ++l) {
      const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, light_towards_[l]);
      const float lit = tracer_.occluded(origin, light_towards_[l]) ? 0.0f : 1.0f;
      ++rays;
      direct +=
          msm_direct_light(glm::vec3(light_irradiance_[l]), float(glm::dot(n, light_towards_[l])), glm::vec3(lit));
    }
    const glm::vec3 colour = msm_surface_radiance(tracer_.albedo(hit), direct, MSM_AMBIENT);
    write_surface(x, y, n_dot_l, hit);
    write_radiance(x, y, colour);
    if (scattering_) add_scattering(x, y, dir, hit.p, colour, rays);
  }

  // scattering: the visible fraction of the ray from the camera to `end` over every light
  // (std_error, samples into the visibility image), the in-scattered radiance summed over the
  // lights, and the composite over surface_radiance (msm/scattering.h's sum over the lights).
  void add_scattering(int x, int y, const glm::dvec3& dir, const glm::dvec3& end, const glm::vec3& surface_radiance,
                      std::uint64_t& rays) {
    const scene::Medium& m = *scene_.medium;
    const double s = glm::length(end - camera_);
    Rng rng = pixel_rng(settings_.seed, x, y, Effect::scattering);
    std::vector<float> phase(light_towards_.size());
    std::vector<ScatteringLight> lights(light_towards_.size());
    for (std::size_t l = 0; l < lights.size(); ++l) {
      phase[l] = msm_scattering_phase_term(m.extinction, m.scattering_albedo, m.g, glm::vec3(light_towards_[l]),
                                           glm::vec3(dir));
      lights[l] = {light_towards_[l], double(msm_scattering_light_weight(glm::vec3(light_irradiance_[l]), phase[l]))};
    }
    // Spot and point lights after the directional ones: f E varies along the ray (its samples' mean).
    for (const scene::LocalLight& local : scene_.local_lights) lights.push_back({.local = &local});
    const ScatteringSample e = scattering_along_ray(ctx_, m, camera_, dir, s, lights, rng);
    rays += e.rays;
    row_sum[y] += e.visible;
    float* v = result_.visibility.pixels().data() + pixel(x, y) * result_.visibility.channels();
    v[0] = float(e.visible);
    v[2] = float(e.samples);
    v[3] = float(e.std_error);
    ScatteringSum sum = msm_scattering_sum_none();
    for (std::size_t l = 0; l < lights.size(); ++l)
      sum = l < phase.size() ? msm_scattering_add_light(sum, glm::vec3(light_irradiance_[l]), m.extinction, phase[l],
                                                        float(s), float(e.light_visible[l]))
                             : msm_scattering_add_light(sum, glm::vec3(e.light_unshadowed[l]), m.extinction, 1.0f,
                                                        float(s), float(e.light_visible[l]));
    const glm::vec3 in = sum.inscattered;
    float* q = result_.scattering.pixels().data() + pixel(x, y) * 4;
    q[0] = in.r, q[1] = in.g, q[2] = in.b, q[3] = float(s);
    write_radiance(x, y, msm_scattering_sum_radiance(surface_radiance, m.extinction, float(s), sum));
  }

  const scene::Scene& scene_;
  const Settings& settings_;
  const EffectContext& ctx_;
  const Tracer& tracer_;
  const EnvironmentLighting* lighting_; // environment only
  Result& result_;
  const int W_, H_;
  const bool mc_, scattering_;
  const EffectFunction effect_;
  const glm::dmat4 inv_vp_;
  const glm::dvec3 irradiance_, camera_;
  const msm::probe::CubeMap probe_;
  std::vector<glm::dvec3> light_towards_, light_irradiance_; // scattering: every light's

 public:
  std::vector<double> row_sum;             // per row: the visibility summed over its pixels
  std::vector<std::size_t> row_background; // per row: pixels without a surface
};

Result render_in_arena(const scene::Scene& scene, const Settings& settings) {
  const auto start = std::chrono::steady_clock::now();
  Result result;
  const int W = settings.width, H = settings.height;
  const bool scattering = settings.effect == Effect::scattering;
  if (scattering && !scene.medium)
    throw std::invalid_argument("the scattering effect needs a scene with a \"medium\" (extinction, albedo, phase)");
  check_local_lights(scene, settings);
  std::optional<EnvironmentLighting> lighting;
  if (settings.effect == Effect::environment) lighting.emplace(scene, settings.probe_lights); // throws without a probe
  const Tracer tracer(scene);
  result.build_seconds = util::seconds_since(start);

  const TracedLight light = checked_light(scene, settings);
  result.light_shape = light.shape;
  result.light_extent_deg = light.extent_deg;
  result.light_width_deg = light.width_deg;
  result.light_height_deg = light.height_deg;
  const EffectContext ctx = effect_context(tracer, scene, settings, light);
  create_images(result, settings);
  PixelTracer pixels(scene, settings, ctx, lighting ? &*lighting : nullptr, result);
  result.probe_background = bool(scene.probe);

  std::atomic<std::uint64_t> rays{0};
  std::atomic<std::size_t> rows_done{0};
  std::mutex progress_mutex;
  std::size_t progress_reported = 0;
  const std::size_t progress_step = std::max<std::size_t>(1, std::size_t(H) / 200);
  const auto trace_start = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<int>(0, H, 1), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y != range.end(); ++y) {
      rays += pixels.trace_row(y);
      const std::size_t done = ++rows_done;
      if (settings.progress && (done % progress_step == 0 || done == std::size_t(H))) {
        std::lock_guard lock(progress_mutex);
        if (done > progress_reported) {
          progress_reported = done;
          settings.progress(Progress{done, std::size_t(H), util::seconds_since(start)});
        }
      }
    }
  });
  result.render_seconds = util::seconds_since(trace_start);
  result.rays = rays.load();
  double sum = 0.0;
  for (int y = 0; y < H; ++y) {
    sum += pixels.row_sum[y];
    result.background_pixels += pixels.row_background[y];
  }
  const std::size_t covered = scattering ? std::size_t(W) * H : std::size_t(W) * H - result.background_pixels;
  result.mean_visibility = covered ? sum / double(covered) : 1.0;
  result.threads =
      unsigned(std::min<std::size_t>(tbb::this_task_arena::max_concurrency(),
                                     tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
  return result;
}

} // namespace
} // namespace msm::reference
