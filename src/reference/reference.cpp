// msm::reference: settings, the camera, the per-pixel loop (TBB) and the output images.
#include "msm/reference/reference.h"

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

namespace {

void check_range(const char* what, long long value, long long lo, long long hi) {
  if (value < lo || value > hi)
    throw std::invalid_argument(fmt::format("{} {} is out of range [{}, {}]", what, value, lo, hi));
}

void check_angle(const char* what, const std::optional<double>& deg) {
  if (deg && !(std::isfinite(*deg) && *deg >= 0.0 && *deg < 90.0))
    throw std::invalid_argument(fmt::format("{} {} degrees is out of range [0, 90)", what, *deg));
}

} // namespace

void validate(const Settings& s) {
  check_range("width", s.width, 1, kMaxSide);
  check_range("height", s.height, 1, kMaxSide);
  check_range("samples", s.samples, 1, kMaxSamples);
  check_range("shadow map size", s.shadow_size, 1, kMaxShadowSize);
  check_range("max crossings", s.max_crossings, 1, kMaxCrossings);
  check_range("threads", s.threads, 0, kMaxThreads);
  [[maybe_unused]] const FilterKernel kernel(s.filter_size, s.filter_sigma); // throws for a bad size or sigma
  check_angle("light extent", s.light_extent_deg);
  check_angle("light width", s.light_width_deg);
  check_angle("light height", s.light_height_deg);
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

Result render_in_arena(const scene::Scene& scene, const Settings& settings) {
  const auto start = std::chrono::steady_clock::now();
  Result result;
  const int W = settings.width, H = settings.height;
  const bool mc = is_monte_carlo(settings.effect);

  const bool scattering = settings.effect == Effect::scattering;
  if (scattering && !scene.medium)
    throw std::invalid_argument("the scattering effect needs a scene with a \"medium\" (extinction, albedo, phase)");
  const bool environment = settings.effect == Effect::environment;
  // Spot and point lights: the hard and soft effects shade every light of the scene (trace_lights).
  const bool local_lights = !scene.local_lights.empty();
  if (local_lights && settings.effect != Effect::hard && settings.effect != Effect::soft &&
      settings.effect != Effect::translucent)
    throw std::invalid_argument(fmt::format("the {} effect traces directional lights only; a scene with spot or point "
                                            "lights is traced by the hard, soft and translucent effects",
                                            to_string(settings.effect)));
  if (local_lights &&
      (settings.light_extent_deg || settings.light_shape || settings.light_width_deg || settings.light_height_deg))
    throw std::invalid_argument("the light overrides (extent, shape, width, height) change a scene's one directional "
                                "light; a scene with spot or point lights is traced as it declares its lights");
  if (local_lights && settings.effect == Effect::soft)
    for (const scene::DirectionalLight& l : scene.lights)
      if (l.rectangular() || !l.sub_lights.empty())
        throw std::invalid_argument("the soft effect traces a scene with spot or point lights with disc-shaped "
                                    "directional lights only (no rectangles, no probe lights)");
  std::optional<EnvironmentLighting> lighting;
  if (environment) lighting.emplace(scene, settings.probe_lights); // throws without a probe
  const Tracer tracer(scene);
  result.build_seconds = util::seconds_since(start);

  // A scene of spot and point lights only has no directional light to frame.
  const scene::DirectionalLight first_light = scene.lights.empty() ? scene::DirectionalLight{} : scene.light();
  EffectContext ctx{tracer,
                    settings,
                    scene.lights.empty() ? LightFrame{} : scene.light_frame(),
                    {},
                    FilterKernel(settings.filter_size, settings.filter_sigma)};
  ctx.towards_light = ctx.frame.towards_light;
  ctx.texel_x = ctx.frame.x_axis * (ctx.frame.extent.x / settings.shadow_size);
  ctx.texel_y = ctx.frame.y_axis * (ctx.frame.extent.y / settings.shadow_size);
  // The soft light's axes: the light-space axes, made exactly orthonormal to towards_light.
  ctx.light_x = glm::normalize(ctx.frame.x_axis - glm::dot(ctx.frame.x_axis, ctx.towards_light) * ctx.towards_light);
  ctx.light_y = glm::cross(ctx.towards_light, ctx.light_x);
  if (glm::dot(ctx.light_y, ctx.frame.y_axis) < 0.0) ctx.light_y = -ctx.light_y;
  const TracedLight light = traced_light(first_light, settings);
  if (!(std::isfinite(light.extent_deg) && light.extent_deg >= 0.0 && light.extent_deg < 90.0))
    throw std::invalid_argument(fmt::format("light extent {} degrees is out of range [0, 90)", light.extent_deg));
  result.light_shape = light.shape;
  result.light_extent_deg = light.extent_deg;
  result.light_width_deg = light.width_deg;
  result.light_height_deg = light.height_deg;
  const auto half_tan = [](double deg) { return std::tan(deg * std::numbers::pi / 360.0); };
  ctx.light_shape = light.shape;
  ctx.half_x = half_tan(result.light_width_deg);
  ctx.half_y = half_tan(result.light_height_deg);
  const EffectFunction effect = effect_function(settings.effect);

  std::vector<std::string> names{"visibility", "background"};
  if (mc) names.insert(names.end(), {"sample_count", "std_error"});
  result.visibility = image::Image(W, H, names);
  // translucent: the transmittance per RGB channel (coloured shadows; "visibility" is their
  // mean), in an image of its own (an image has at most 4 channels).
  const bool coloured = settings.effect == Effect::translucent;
  if (coloured) result.visibility_rgb = image::Image(W, H, {"visibility_r", "visibility_g", "visibility_b"}, 1.0f);
  result.radiance = image::Image(W, H, 3);
  result.surface = image::Image(W, H, {"n_dot_l", "object"});
  if (scattering) result.scattering = image::Image(W, H, {"R", "G", "B", "length"});
  if (environment) result.irradiance = image::Image(W, H, {"R", "G", "B", "std_error"});
  for (std::size_t i = 0; i < result.surface.pixel_count(); ++i) result.surface.pixels()[2 * i + 1] = -1.0f;
  result.samples = mc ? settings.samples : 1;

  // Camera: unproject NDC depth 0 and 1 with the inverse of the rasterizer's matrix.
  const glm::dmat4 inv_vp = glm::inverse(glm::dmat4(scene.camera_view_projection(float(W) / float(H))));
  const auto unproject = [&](double nx, double ny, double depth) {
    const glm::dvec4 q = inv_vp * glm::dvec4(nx, ny, depth, 1.0);
    return glm::dvec3(q) / q.w;
  };
  const glm::dvec3 irradiance(first_light.irradiance);
  const glm::dvec3 camera(scene.camera.position);
  // A probe-lit scene's background: its probe as the renderer loads it (GpuScene), by texel.
  msm::probe::CubeMap probe;
  if (scene.probe) try {
      probe = msm::probe::load_probe(scene.probe->file.string(), scene.probe->size, scene.probe->rotation_deg,
                                     scene.probe->intensity);
    } catch (const msm::probe::ProbeError& e) { throw std::invalid_argument(e.what()); }
  result.probe_background = bool(scene.probe);
  const auto background = [&](const glm::dvec3& dir) {
    if (!probe.size) return glm::vec3(0.0f);
    const glm::ivec3 t = msm_cube_texel(glm::vec3(dir), probe.size);
    return probe.at(t.z, t.x, t.y);
  };
  // scattering: every light of the scene (the first is ctx's), its direction and irradiance.
  std::vector<glm::dvec3> light_towards, light_irradiance;
  if (scattering)
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      light_towards.push_back(l == 0 ? ctx.towards_light : scene.light_frame(l).towards_light);
      light_irradiance.emplace_back(scene.lights[l].irradiance);
    }

  std::vector<double> row_sum(H, 0.0);
  std::vector<std::size_t> row_background(H, 0);
  std::atomic<std::uint64_t> rays{0};
  std::atomic<std::size_t> rows_done{0};
  std::mutex progress_mutex;
  std::size_t progress_reported = 0;
  const std::size_t progress_step = std::max<std::size_t>(1, std::size_t(H) / 200);
  const int channels = result.visibility.channels();
  float* vis = result.visibility.pixels().data();
  float* rad = result.radiance.pixels().data();
  float* surf = result.surface.pixels().data();
  float* vis_rgb = coloured ? result.visibility_rgb.pixels().data() : nullptr;
  // scattering: the visible fraction of the ray from the camera to `end` over every light
  // (std_error, samples into the visibility image), the in-scattered radiance summed over the
  // lights, and the composite over surface_radiance (msm/scattering.h's sum over the lights).
  const auto add_scattering = [&](int x, int y, const glm::dvec3& dir, const glm::dvec3& end,
                                  const glm::vec3& surface_radiance, std::uint64_t& row_rays) {
    const scene::Medium& m = *scene.medium;
    const double s = glm::length(end - camera);
    Rng rng = pixel_rng(settings.seed, x, y, Effect::scattering);
    std::vector<float> phase(light_towards.size());
    std::vector<ScatteringLight> lights(light_towards.size());
    for (std::size_t l = 0; l < lights.size(); ++l) {
      phase[l] = msm_scattering_phase_term(m.extinction, m.scattering_albedo, m.g, glm::vec3(light_towards[l]),
                                           glm::vec3(dir));
      lights[l] = {light_towards[l], double(msm_scattering_light_weight(glm::vec3(light_irradiance[l]), phase[l]))};
    }
    const ScatteringSample e = scattering_along_ray(ctx, m, camera, dir, s, lights, rng);
    row_rays += e.rays;
    row_sum[y] += e.visible;
    float* v = result.visibility.pixels().data() + (std::size_t(y) * W + x) * result.visibility.channels();
    v[0] = float(e.visible);
    v[2] = float(e.samples);
    v[3] = float(e.std_error);
    ScatteringSum sum = msm_scattering_sum_none();
    for (std::size_t l = 0; l < lights.size(); ++l)
      sum = msm_scattering_add_light(sum, glm::vec3(light_irradiance[l]), m.extinction, phase[l], float(s),
                                     float(e.light_visible[l]));
    const glm::vec3 in = sum.inscattered;
    const glm::vec3 all = msm_scattering_sum_radiance(surface_radiance, m.extinction, float(s), sum);
    float* q = result.scattering.pixels().data() + (std::size_t(y) * W + x) * 4;
    q[0] = in.r, q[1] = in.g, q[2] = in.b, q[3] = float(s);
    float* c = result.radiance.pixels().data() + (std::size_t(y) * W + x) * 3;
    c[0] = all.r, c[1] = all.g, c[2] = all.b;
  };
  const auto trace_start = std::chrono::steady_clock::now();

  tbb::parallel_for(tbb::blocked_range<int>(0, H, 1), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y != range.end(); ++y) {
      std::uint64_t row_rays = 0;
      for (int x = 0; x < W; ++x) {
        const double nx = (x + 0.5) / W * 2.0 - 1.0, ny = (y + 0.5) / H * 2.0 - 1.0;
        const glm::dvec3 near = unproject(nx, ny, 0.0), far = unproject(nx, ny, 1.0);
        const double length = glm::length(far - near);
        const glm::dvec3 dir = (far - near) / length;
        float* v = vis + (std::size_t(y) * W + x) * channels;
        float* c = rad + (std::size_t(y) * W + x) * 3;
        SurfaceHit hit;
        ++row_rays;
        // The visible surface is the closest opaque one: translucent surfaces (opacity
        // < 1) are looked through, as the renderer's shadow buffer does, and so are the back
        // faces of single-sided materials, which the rasterizer culls.
        bool found = tracer.closest(near, dir, length, hit);
        const auto hidden = [&](const SurfaceHit& h) {
          const scene::Material& m = tracer.material(h);
          return m.translucent() || (!m.double_sided && glm::dot(h.normal, dir) > 0.0);
        };
        for (int crossed = 0; found && hidden(hit) && crossed < kMaxCrossings; ++crossed) {
          const glm::dvec3 beyond = offset_origin(hit.p, hit.normal, hit.scale, dir);
          found = tracer.closest(beyond, dir, length - glm::length(beyond - near), hit);
          ++row_rays;
        }
        if (!found) {
          v[0] = 1.0f;
          v[1] = 1.0f;
          ++row_background[y];
          const glm::vec3 sky = background(dir);
          float* c = rad + (std::size_t(y) * W + x) * 3;
          c[0] = sky.r, c[1] = sky.g, c[2] = sky.b;
          if (scattering) add_scattering(x, y, dir, far, sky, row_rays);
          continue; // sample_count and std_error 0 (scattering: the ray's)
        }
        Rng rng = pixel_rng(settings.seed, x, y, settings.effect);
        // Shading: interpolated normal turned towards the viewer.
        glm::dvec3 n = tracer.shading_normal(hit);
        if (glm::dot(hit.normal, dir) > 0.0) n = -n;
        if (local_lights) {
          const LightsSample e = trace_lights(ctx, hit, n, rng);
          row_rays += e.rays;
          v[0] = float(e.visible);
          if (mc) {
            v[2] = float(e.samples);
            v[3] = float(e.std_error);
          }
          row_sum[y] += e.visible;
          if (vis_rgb) {
            float* t = vis_rgb + (std::size_t(y) * W + x) * 3;
            t[0] = float(e.visible_rgb.r), t[1] = float(e.visible_rgb.g), t[2] = float(e.visible_rgb.b);
          }
          const glm::vec3 colour = msm_surface_radiance(tracer.albedo(hit), glm::vec3(e.direct), MSM_AMBIENT);
          float* q = surf + (std::size_t(y) * W + x) * 2;
          q[0] = float(e.n_dot_l);
          q[1] = float(hit.object);
          c[0] = colour.r, c[1] = colour.g, c[2] = colour.b;
          continue;
        }
        if (environment) {
          const EnvironmentSample e = environment_irradiance(ctx, *lighting, hit, n, dir, rng);
          row_rays += e.rays;
          const double lum0 = msm_luminance(glm::vec3(e.unoccluded));
          const double visible = lum0 > 0.0 ? msm_luminance(glm::vec3(e.irradiance)) / lum0 : 0.0;
          v[0] = float(visible);
          v[2] = float(e.samples);
          v[3] = float(lum0 > 0.0 ? e.std_error / lum0 : 0.0);
          row_sum[y] += visible;
          const glm::vec3 direct = msm_direct_light(glm::vec3(e.irradiance), 1.0f, glm::vec3(1.0f));
          const glm::vec3 colour = msm_surface_radiance(tracer.albedo(hit), direct, MSM_AMBIENT);
          float* q = surf + (std::size_t(y) * W + x) * 2;
          q[0] = float(glm::dot(n, ctx.towards_light));
          q[1] = float(hit.object);
          c[0] = colour.r, c[1] = colour.g, c[2] = colour.b;
          float* ir = result.irradiance.pixels().data() + (std::size_t(y) * W + x) * 4;
          ir[0] = float(e.irradiance.r), ir[1] = float(e.irradiance.g), ir[2] = float(e.irradiance.b);
          ir[3] = float(e.std_error);
          continue;
        }
        const EffectResult e = effect(ctx, hit, rng);
        row_rays += e.rays;
        v[0] = float(e.value);
        if (mc) {
          v[2] = float(e.samples);
          v[3] = float(e.std_error);
        }
        const glm::vec3 rgb = e.rgb ? glm::vec3(*e.rgb) : glm::vec3(float(e.value));
        if (vis_rgb) {
          float* t = vis_rgb + (std::size_t(y) * W + x) * 3;
          t[0] = rgb.r;
          t[1] = rgb.g;
          t[2] = rgb.b;
        }
        if (!scattering) row_sum[y] += e.value;
        // Per channel where the effect gives a visibility per channel (translucent).
        const float n_dot_l = float(glm::dot(n, ctx.towards_light));
        glm::vec3 direct = e.lit ? msm_direct_light(glm::vec3(irradiance), float(*e.lit), glm::vec3(1.0f))
                                 : msm_direct_light(glm::vec3(irradiance), n_dot_l, rgb);
        // scattering: the surface lit by every light, each with its exact (hard) shadow, as the
        // renderer shades it (msm/shading.h's sum over the lights); the first light's is e.
        for (std::size_t l = 1; scattering && l < light_towards.size(); ++l) {
          const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, light_towards[l]);
          const float lit = tracer.occluded(origin, light_towards[l]) ? 0.0f : 1.0f;
          ++row_rays;
          direct +=
              msm_direct_light(glm::vec3(light_irradiance[l]), float(glm::dot(n, light_towards[l])), glm::vec3(lit));
        }
        const glm::vec3 colour = msm_surface_radiance(tracer.albedo(hit), direct, MSM_AMBIENT);
        float* q = surf + (std::size_t(y) * W + x) * 2;
        q[0] = n_dot_l;
        q[1] = float(hit.object);
        c[0] = colour.r;
        c[1] = colour.g;
        c[2] = colour.b;
        if (scattering) add_scattering(x, y, dir, hit.p, colour, row_rays);
      }
      rays += row_rays;
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
    sum += row_sum[y];
    result.background_pixels += row_background[y];
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
