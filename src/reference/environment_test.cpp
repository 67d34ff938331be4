// Tests of the environment effect (image-based lighting with exact visibility) against answers
// that do not use its sampler: a plane under the procedural sky-and-sun probe against quadrature
// over the cube's texels (full probe) and against quadrature over the extracted rectangles
// (--extracted-lights), and a box's shadow that takes the sun's share away.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "internal.h"
#include "msm/light_probe.h"
#include "msm/probe/probe.h"
#include "msm/reference/reference.h"
#include "msm/scene/scene.h"
#include "msm/test/figures.h"

namespace {

using namespace msm::reference;
using msm::scene::Scene;

constexpr int kProbeSize = 32;

Scene sky_scene(const std::string& camera, const std::string& objects) {
  const std::string json = R"({"msm_scene": 1, "camera": )" + camera +
                           R"(, "probe": {"file": "sky", "lights": 32, "size": )" + std::to_string(kProbeSize) +
                           R"(}, "objects": [)" + objects + "]}";
  return msm::scene::load_scene_json(json, std::filesystem::current_path(), "test.json");
}

const std::string kPlane = R"({"primitive": {"type": "plane", "size": [40, 40]}})";
const std::string kTopCamera = R"({"position": [0, 3, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov_y_deg": 45})";

// ∫ L max(n·ω, 0) dω by the midpoint rule over the cube's texels (texel weight and centre
// direction), restricted to texels where keep(L) holds, with L − minus(L) as the radiance.
template <class Keep>
glm::dvec3 quadrature(const msm::probe::CubeMap& cube, const glm::dvec3& n, Keep keep, glm::vec3 minus) {
  glm::dvec3 sum(0.0);
  const int m = cube.size;
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const float u = (2.0f * i + 1.0f) / m - 1.0f, v = (2.0f * j + 1.0f) / m - 1.0f;
        const glm::dvec3 d = glm::normalize(glm::dvec3(msm::msm_cube_direction(face, u, v)));
        const glm::vec3 L = cube.at(face, i, j);
        if (!keep(L)) continue;
        sum +=
            double(msm::msm_cube_texel_weight(u, v, float(m))) * std::max(glm::dot(n, d), 0.0) * glm::dvec3(L - minus);
      }
  return sum;
}

struct Mean {
  glm::dvec3 irradiance{0.0};
  double std_error = 0.0; // of the luminance of the mean
};

// The mean irradiance over every pixel (all on the plane), and its standard error.
Mean mean_irradiance(const Result& r) {
  Mean m;
  const auto& p = r.irradiance.pixels();
  const std::size_t n = r.irradiance.pixel_count();
  double variance = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    m.irradiance += glm::dvec3(p[4 * k], p[4 * k + 1], p[4 * k + 2]);
    variance += double(p[4 * k + 3]) * p[4 * k + 3];
  }
  m.irradiance /= double(n);
  m.std_error = std::sqrt(variance) / double(n);
  return m;
}

Settings environment_settings(int samples) {
  Settings s;
  s.effect = Effect::environment;
  s.width = 16;
  s.height = 9;
  s.samples = samples;
  return s;
}

double lum(const glm::dvec3& c) { return double(msm::msm_luminance(glm::vec3(c))); }

TEST(Environment, UnoccludedPlaneReceivesTheProbesIrradiance) {
  const Scene scene = sky_scene(kTopCamera, kPlane);
  const Result r = render(scene, environment_settings(64));
  ASSERT_EQ(r.background_pixels, 0u);
  const Mean m = mean_irradiance(r);
  const msm::probe::CubeMap cube = msm::probe::load_probe("sky", kProbeSize);
  const glm::dvec3 expected = quadrature(
      cube, {0.0, 1.0, 0.0}, [](glm::vec3) { return true; }, glm::vec3(0.0f));
  EXPECT_LT(std::abs(lum(m.irradiance) - lum(expected)), 3.0 * m.std_error + 1e-4 * lum(expected));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.irradiance[c], expected[c], 0.01 * expected[c]) << "channel " << c;
  // The radiance is the shading formula's with this irradiance (albedo 0.8 by default).
  const float* radiance = r.radiance.pixels().data();
  const float* e = r.irradiance.pixels().data();
  EXPECT_NEAR(radiance[0], 0.8 * (e[0] / std::numbers::pi + msm::MSM_AMBIENT), 1e-4 * radiance[0]);
  EXPECT_NEAR(r.mean_visibility, 1.0, 1e-12); // nothing occludes
}

// ∫ max(n·d, 0) dω / F over a rectangular light (its frame's axes, Scene::light_frame) by the
// midpoint rule on its plane at unit distance (dω = dA / r³): what --extracted-lights integrates for
// it, without its sampler; the same as msm_cone_cosine where the whole light is above the horizon.
double rectangle_cosine(const Scene& scene, const msm::scene::DirectionalLight& l, const glm::dvec3& n) {
  const msm::scene::LightFrame f = scene.light_frame(l);
  const glm::dvec3 z = glm::normalize(glm::dvec3(l.towards_light));
  const glm::dvec3 x = glm::normalize(f.x_axis - glm::dot(f.x_axis, z) * z), y = glm::cross(z, x);
  // Lines and points (a region one texel wide has no variance along that axis) as their limit.
  const glm::vec2 t = glm::max(l.tan_half_extents(), glm::vec2(1e-4f));
  const int k = 400;
  double sum = 0.0;
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const double a = ((i + 0.5) / k * 2.0 - 1.0) * t.x, b = ((j + 0.5) / k * 2.0 - 1.0) * t.y;
      const glm::dvec3 p = z + a * x + b * y;
      const double r = glm::length(p);
      sum += std::max(glm::dot(n, p) / r, 0.0) / (r * r * r);
    }
  return sum * (4.0 * t.x * t.y / (double(k) * k)) / double(msm::msm_rect_light_facing_integral(t));
}

// The factor the renderer's shading gives light l on a surface of normal n (shading.glsl,
// direct_light: msm_light_cosine with the light frame's x axis and the rectangle's extents).
double light_cosine(const Scene& scene, const msm::scene::DirectionalLight& l, const glm::dvec3& n) {
  return double(msm::msm_light_cosine(glm::vec3(n), l.towards_light, glm::vec3(scene.light_frame(l).x_axis),
                                      l.rectangle_extents(), l.cone_half_angle()));
}

TEST(Environment, UnoccludedPlaneUnderTheAreaLightsMatchesTheirClosedForm) {
  const Scene scene = sky_scene(kTopCamera, kPlane);
  Settings s = environment_settings(64);
  s.probe_lights = true;
  const Result r = render(scene, s);
  const Mean m = mean_irradiance(r);
  glm::dvec3 expected(0.0);
  for (const auto& l : scene.lights) {
    ASSERT_TRUE(l.rectangular()); // the probe's lights (Kneiphof §4.1.2)
    const double truth = rectangle_cosine(scene, l, {0.0, 1.0, 0.0});
    expected += glm::dvec3(l.irradiance) * truth;
    // The shading's factor (msm_light_cosine: the rectangle clipped by the horizon) is this
    // integral for every light, straddling the horizon or not (quadrature error < 2e-5).
    EXPECT_NEAR(light_cosine(scene, l, {0.0, 1.0, 0.0}), truth, 1e-4) << l.towards_light.y;
    // Wholly above the horizon (its corners too), the cone of its solid angle gives the same: n·l.
    const glm::vec2 t = l.tan_half_extents();
    if (l.towards_light.y > std::sin(std::atan(glm::length(t)))) {
      EXPECT_NEAR(msm::msm_cone_cosine(l.towards_light.y, l.cone_half_angle()),
                  rectangle_cosine(scene, l, {0.0, 1.0, 0.0}), 1e-4);
    }
  }
  EXPECT_LT(std::abs(lum(m.irradiance) - lum(expected)), 3.0 * m.std_error + 1e-4 * lum(expected));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.irradiance[c], expected[c], 0.01 * expected[c]) << "channel " << c;
}

TEST(Environment, BoxShadowTakesTheSunsShareAway) {
  // A box of half-diagonal h at height 2.5 over the plane: its shadow's centre ps; an open point po.
  const glm::dvec3 box(0.0, 2.5, 0.0);
  const double half = 0.25, h = half * std::sqrt(3.0);
  const msm::probe::CubeMap cube = msm::probe::load_probe("sky", kProbeSize);
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.4, 0.6, -0.3)); // sky_probe's
  const glm::dvec3 ps = box - (box.y / sun.y) * sun, po = ps + glm::dvec3(-1.5, 0.0, 1.0);
  const std::string camera = R"({"position": [-4.5, 4, 4.5], "target": [)" + std::to_string(ps.x - 0.75) + ", 0, " +
                             std::to_string(ps.z + 0.5) + R"(], "fov_y_deg": 40})";
  const std::string cube_json =
      R"({"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]}, "transform": {"translate": [0, 2.5, 0]}})";
  const Scene scene = sky_scene(camera, kPlane + ", " + cube_json);
  Settings s = environment_settings(256);
  s.width = 48;
  s.height = 27;
  const Result r = render(scene, s);
  const glm::mat4 vp = scene.camera_view_projection(float(s.width) / float(s.height));
  const auto pixel = [&](const glm::dvec3& p) {
    const glm::vec4 c = vp * glm::vec4(glm::vec3(p), 1.0f);
    const int x = int(std::floor((c.x / c.w + 1.0f) * 0.5f * s.width)),
              y = int(std::floor((c.y / c.w + 1.0f) * 0.5f * s.height));
    EXPECT_TRUE(x >= 0 && x < s.width && y >= 0 && y < s.height);
    const float* e = r.irradiance.pixels().data() + (std::size_t(y) * s.width + x) * 4;
    return std::pair(glm::dvec3(e[0], e[1], e[2]), double(e[3]));
  };
  const auto [shadowed, se_s] = pixel(ps);
  const auto [open, se_o] = pixel(po);
  // The sun's share: the texels brighter than the sky (the sky's radiance: the texel opposite the sun).
  const msm::MsmCubeCoord away = msm::msm_cube_coord(-glm::vec3(sun));
  const glm::vec3 sky =
      cube.at(away.face, int((away.uv.x + 1.0f) * 0.5f * kProbeSize), int((away.uv.y + 1.0f) * 0.5f * kProbeSize));
  const glm::dvec3 sun_share = quadrature(
      cube, {0.0, 1.0, 0.0}, [&](glm::vec3 L) { return msm::msm_luminance(L) > 1.01f * msm::msm_luminance(sky); }, sky);
  // Besides the sun, the box hides at most the sky within its bounding sphere seen from ps.
  const double d = glm::length(box - ps);
  const double sky_hidden = lum(glm::dvec3(sky)) * 2.0 * std::numbers::pi * (1.0 - std::sqrt(1.0 - h * h / (d * d)));
  const double drop = lum(open) - lum(shadowed), tolerance = 3.0 * std::hypot(se_s, se_o);
  EXPECT_GT(drop, lum(sun_share) - tolerance);
  EXPECT_LT(drop, lum(sun_share) + sky_hidden + tolerance);
  EXPECT_GT(lum(sun_share), 0.5 * lum(open)); // the test means something: the sun is most of the light
}

// ∫ L max(n·ω, 0) dω of the piecewise constant probe exactly as the estimator integrates it
// (each texel's radiance over the texel), by the midpoint rule over k x k parts of each texel
// (msm_cube_texel_weight at the finer size): within 1e-6 relative of the exact integral here, where
// the midpoint rule over whole texels (quadrature above) is off by the cosine's curvature.
glm::dvec3 piecewise_constant_irradiance(const msm::probe::CubeMap& cube, const glm::dvec3& n, int k) {
  glm::dvec3 sum(0.0);
  const int m = cube.size, fine = m * k;
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < fine; ++j)
      for (int i = 0; i < fine; ++i) {
        const float u = msm::msm_cube_face_coordinate(i, 0.5f, float(fine)),
                    v = msm::msm_cube_face_coordinate(j, 0.5f, float(fine));
        const glm::dvec3 d = glm::normalize(glm::dvec3(msm::msm_cube_direction(face, u, v)));
        sum += double(msm::msm_cube_texel_weight(u, v, float(fine))) * std::max(glm::dot(n, d), 0.0) *
               glm::dvec3(cube.at(face, i / k, j / k));
      }
  return sum;
}

// Pixels of one render as independent runs: each pixel draws from its own generator.
struct PixelStatistics {
  double mean = 0.0, std_error = 0.0; // of the pixels' irradiance luminance, from their spread
  double mean_relative_error = 0.0;   // each pixel's own std_error over its luminance, averaged
};
PixelStatistics pixel_statistics(const Result& r) {
  const auto& p = r.irradiance.pixels();
  const std::size_t n = r.irradiance.pixel_count();
  double sum = 0.0, squares = 0.0, relative = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double y = lum(glm::dvec3(p[4 * k], p[4 * k + 1], p[4 * k + 2]));
    sum += y;
    squares += y * y;
    relative += p[4 * k + 3] / y;
  }
  PixelStatistics s;
  s.mean = sum / double(n);
  s.std_error = std::sqrt(std::max(0.0, (squares - sum * s.mean) / double(n - 1)) / double(n));
  s.mean_relative_error = relative / double(n);
  return s;
}

// The estimator is unbiased: on the unoccluded plane under the procedural sky (every pixel the
// same irradiance), the mean of 1296 independent pixels of 256 samples each is the probe's exact
// irradiance within 4 standard errors of that mean (measured from the pixels' spread), for both
// ways of sampling the probe; the standard error is below 0.1% of it, so this is a sharp check.
TEST(Environment, EstimatorIsUnbiasedOnTheUnoccludedPlane) {
  const Scene scene = sky_scene(kTopCamera, kPlane);
  const msm::probe::CubeMap cube = msm::probe::load_probe("sky", kProbeSize);
  const double expected = lum(piecewise_constant_irradiance(cube, {0.0, 1.0, 0.0}, 16));
  Settings s = environment_settings(256);
  s.width = 48;
  s.height = 27;
  for (auto sampling : {detail::ProbeSampling::compensated, detail::ProbeSampling::luminance}) {
    detail::set_probe_sampling(sampling);
    const PixelStatistics m = pixel_statistics(render(scene, s));
    const char* name = sampling == detail::ProbeSampling::compensated ? "compensated" : "luminance";
    std::printf("[unbiased] %s: mean %.6f, exact %.6f, standard error %.6f (%.2f of them off)\n", name, m.mean,
                expected, m.std_error, (m.mean - expected) / m.std_error);
    EXPECT_LT(std::abs(m.mean - expected), 4.0 * m.std_error) << name;
    EXPECT_LT(m.std_error, 1e-3 * expected) << name;
  }
  detail::set_probe_sampling(detail::ProbeSampling::compensated);
}

// With occlusion (the box's shadow and contact shadows on the plane, under the sky and its sun):
// the compensated sampling (with each sampler) estimates the irradiance that plain importance
// sampling of the probe does. The latter with independent samples, whose std_error is the standard
// error (the stratified sampler's is an upper bound); per pixel z = (E_c − E_l) / sqrt(se_c² +
// se_l²) from two independent renders: the mean of z within 4 / sqrt(pixels) of 0 (a bias of a
// tenth of a standard error in every pixel shows), and the mean of z² below 1.3 (1 or less without
// a bias, give or take 0.04 over 1296 pixels; a bias of 0.6 standard errors in every pixel, or of
// 1.2 in a quarter of them, adds 0.36).
TEST(Environment, ProbeSamplingsAgreeUnderOcclusion) {
  const std::string box =
      R"({"primitive": {"type": "box", "size": [1, 1, 1]}, "transform": {"translate": [0, 0.5, 0]}})";
  const std::string camera = R"({"position": [2, 3, 3], "target": [0, 0.3, 0], "fov_y_deg": 50})";
  const Scene scene = sky_scene(camera, kPlane + ", " + box);
  Settings s = environment_settings(256);
  s.width = 48;
  s.height = 27;
  s.sampler = Sampler::independent;
  s.seed = 2;
  detail::set_probe_sampling(detail::ProbeSampling::luminance);
  const Result l = render(scene, s);
  detail::set_probe_sampling(detail::ProbeSampling::compensated);
  for (const Sampler sampler : {Sampler::independent, Sampler::stratified}) {
    s.sampler = sampler;
    s.seed = 1;
    const Result c = render(scene, s);
    const auto& pc = c.irradiance.pixels();
    const auto& pl = l.irradiance.pixels();
    double z_sum = 0.0, z2_sum = 0.0;
    std::size_t n = 0;
    for (std::size_t k = 0; k < c.irradiance.pixel_count(); ++k) {
      const double se = std::hypot(pc[4 * k + 3], pl[4 * k + 3]);
      if (!(se > 0.0)) continue;
      const double z = (lum(glm::dvec3(pc[4 * k], pc[4 * k + 1], pc[4 * k + 2])) -
                        lum(glm::dvec3(pl[4 * k], pl[4 * k + 1], pl[4 * k + 2]))) /
                       se;
      z_sum += z;
      z2_sum += z * z;
      ++n;
    }
    ASSERT_GT(n, 1000u);
    const double z_mean = z_sum / double(n), z2_mean = z2_sum / double(n);
    std::printf("[agree] %s, %zu pixels: mean z %.4f, mean z^2 %.4f\n", std::string(to_string(sampler)).c_str(), n,
                z_mean, z2_mean);
    EXPECT_LT(std::abs(z_mean), 4.0 / std::sqrt(double(n))) << to_string(sampler);
    EXPECT_LT(z2_mean, 1.3) << to_string(sampler);
  }
}

// The guide table finds the texel the whole CDF's binary search finds: for every texel's CDF value,
// the doubles either side of it, every guide entry's k / n and its neighbours, and a million
// uniform points, under both samplings (the compensated one's flat runs of texels never drawn).
TEST(Environment, GuideTableFindsTheBinarySearchesTexel) {
  const Scene scene = sky_scene(kTopCamera, kPlane);
  for (auto sampling : {detail::ProbeSampling::compensated, detail::ProbeSampling::luminance}) {
    detail::set_probe_sampling(sampling);
    const detail::EnvironmentLighting lighting(scene, false);
    ASSERT_EQ(lighting.cdf.size(), std::size_t(6 * kProbeSize * kProbeSize));
    const auto searched = [&](double x) {
      return std::min<std::size_t>(std::upper_bound(lighting.cdf.begin(), lighting.cdf.end(), x) - lighting.cdf.begin(),
                                   lighting.cdf.size() - 1);
    };
    std::vector<double> xs;
    const double n = double(lighting.guide.size());
    for (std::size_t k = 0; k < lighting.cdf.size(); ++k)
      for (double x : {lighting.cdf[k], double(k) / n})
        xs.insert(xs.end(), {x, std::nextafter(x, 0.0), std::nextafter(x, 1.0)});
    msm::util::SplitMix64 rng(7);
    for (int i = 0; i < 1000000; ++i) xs.push_back(rng.uniform());
    std::size_t wrong = 0;
    for (double x : xs)
      if (x >= 0.0 && x < 1.0 && lighting.texel_of(x) != searched(x)) ++wrong;
    EXPECT_EQ(wrong, 0u);
  }
  detail::set_probe_sampling(detail::ProbeSampling::compensated);
}

// The default estimator's noise on the sky with its sun: the pixels' own relative standard error at
// 64 samples, averaged over the unoccluded plane. Measured: 0.0037 with the compensated sampling
// (the default: nearly every probe sample on the sun, the sky the cosine samples'), 0.0905 with
// the luminance one (the sun drawn by some of the probe samples, with the variance of how many).
// Asserted: below 0.01.
TEST(Environment, DefaultEstimatorIsQuietUnderTheSun) {
  const Scene scene = sky_scene(kTopCamera, kPlane);
  Settings s = environment_settings(64);
  s.width = 48;
  s.height = 27;
  const double noise = pixel_statistics(render(scene, s)).mean_relative_error;
  std::printf("[noise] default estimator: mean relative standard error %.4f\n", noise);
  EXPECT_LT(noise, 0.01);
}

TEST(Environment, SceneWithoutProbeIsRefused) {
  const Scene scene = msm::scene::load_scene_json(
      R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "objects": [)" + kPlane + "]}",
      std::filesystem::current_path(), "test.json");
  EXPECT_THROW(render(scene, environment_settings(4)), std::invalid_argument);
}

} // namespace

namespace {

// msm render / reference --lights: re-cutting the probe gives what the scene file's count gives.
TEST(Environment, ProbeLightCountMatchesTheSceneFilesCount) {
  const std::string sky =
      R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "probe": {"file": "sky", "size": 16, "lights": )";
  const std::string rest = R"(}, "objects": [{"primitive": {"type": "plane", "size": [4, 4]}}]})";
  const auto load = [&](int n) {
    return msm::scene::load_scene_json(sky + std::to_string(n) + rest, std::filesystem::current_path(), "t.json");
  };
  Scene scene = load(32);
  for (int count : {16, 3}) { // 3: groups of faces (N < 6)
    msm::scene::set_probe_light_count(scene, count);
    const Scene expected = load(count);
    ASSERT_EQ(scene.lights.size(), expected.lights.size());
    EXPECT_EQ(scene.lights.size(), 1u + std::size_t(count)); // the directional light and the probe's
    EXPECT_EQ(scene.probe->lights, count);
    for (std::size_t k = 0; k < scene.lights.size(); ++k) {
      EXPECT_EQ(scene.lights[k].towards_light, expected.lights[k].towards_light) << k;
      EXPECT_EQ(scene.lights[k].irradiance, expected.lights[k].irradiance) << k;
      EXPECT_EQ(scene.lights[k].angular_extent_deg, expected.lights[k].angular_extent_deg) << k;
    }
  }
  EXPECT_THROW(msm::scene::set_probe_light_count(scene, 0), msm::scene::SceneError);
  EXPECT_THROW(msm::scene::set_probe_light_count(scene, 256), msm::scene::SceneError); // + the directional light
}

} // namespace

namespace {

// Σ E · msm_light_cosine of `lights` on an unoccluded plane of normal n, against quadrature of the
// probe `cube` they were cut from: the relative error of the luminance. light_cosine is the
// renderer's factor (msm_light_cosine with the light frame's axis, the rectangle clipped by the
// plane's horizon); `frame` is any scene, for Scene::light_frame.
double plane_energy_error(const Scene& frame, const std::vector<msm::scene::DirectionalLight>& lights,
                          const msm::probe::CubeMap& cube, const glm::dvec3& n) {
  const glm::dvec3 probe = quadrature(
      cube, n, [](glm::vec3) { return true; }, glm::vec3(0.0f));
  glm::dvec3 sum(0.0);
  for (const auto& l : lights) sum += glm::dvec3(l.irradiance) * light_cosine(frame, l, n);
  return lum(sum) / lum(probe) - 1.0;
}

// The same with each light's unshadowed irradiance from its sub-lights where it has them (the
// shading's sum, shading.glsl add_direct_light).
double plane_energy_error_with_sub_lights(const Scene& frame, const std::vector<msm::scene::DirectionalLight>& lights,
                                          const msm::probe::CubeMap& cube, const glm::dvec3& n) {
  std::vector<msm::scene::DirectionalLight> shaded;
  for (const auto& l : lights) {
    if (l.sub_lights.empty()) shaded.push_back(l);
    shaded.insert(shaded.end(), l.sub_lights.begin(), l.sub_lights.end());
  }
  return plane_energy_error(frame, shaded, cube, n);
}

const std::array<glm::dvec3, 3> kPlaneNormals = {glm::dvec3(0, 1, 0), glm::normalize(glm::dvec3(1, 1, 0)),
                                                 glm::dvec3(0, 0, 1)};

// The scene's lights of the sky (32² faces) cut into `count`: the worst relative error over
// kPlaneNormals, each printed for the counts in `print`.
double sky_plane_energy_error(int count, bool horizon_split, bool print) {
  const std::string json = R"({"msm_scene": 1, "probe": {"file": "sky", "size": 32, "horizon_split": )" +
                           std::string(horizon_split ? "true" : "false") + R"(, "lights": )" + std::to_string(count) +
                           R"(}, "objects": [{"primitive": {"type": "plane", "size": [4, 4]}}]})";
  const Scene scene = msm::scene::load_scene_json(json, std::filesystem::current_path(), "t.json");
  static const msm::probe::CubeMap cube = msm::probe::load_probe("sky", 32);
  double worst = 0.0;
  for (const glm::dvec3& n : kPlaneNormals) {
    const double error = plane_energy_error(scene, scene.lights, cube, n);
    if (print)
      std::printf("[energy%s] %d lights, n = (%.3f, %.3f, %.3f): relative error %+.4f\n", horizon_split ? " split" : "",
                  count, n.x, n.y, n.z, error);
    worst = std::max(worst, std::abs(error));
  }
  return worst;
}

// The issue's energy check, at every count from `first` to 256: the area lights' closed form on an
// unoccluded plane (normals +Y, 45° and +Z) against the probe's irradiance by quadrature, within
// the issue's 1%, or within bound(count) where that is given (the counts where it does not hold).
template <class Bound>
void expect_sky_plane_energy(int first, bool horizon_split, Bound bound) {
  for (int count = first; count <= 256; ++count) {
    const bool print = count <= 6 || count % 16 == 0 || count == 10;
    const bool recorded = count <= 6 || count == 10 || count == 16 || count == 32 || count == 64 || count == 256;
    const double tolerance = bound(count).value_or(0.01);
    const double error = sky_plane_energy_error(count, horizon_split, print);
    EXPECT_LT(error, tolerance) << count << " lights";
    if (recorded)
      msm::test::record_figure("probe_lights.sky_plane_energy." +
                                   std::string(horizon_split ? "horizon_split" : "plain") + "." +
                                   std::to_string(count) + "_lights.worst_relative_error",
                               error,
                               {.below = tolerance,
                                .meaning = "the sky cut into area lights: their irradiance on an unoccluded plane "
                                           "against the probe's, worst relative error over three normals"});
  }
}

// Measured on the sky (32² faces), worst relative error over the three normals, with the lights'
// direction the region's mean direction (msm_region_mean_direction; with Eq. (9)'s centroid on the
// face plane in brackets; docs/results.md, "The sphere's centroid"): 76.0% at 1
// light [77.9%], 44.7% at 2 [44.7%], 18.9% at 3 [19.0%], 5.2% at 4 [4.7%], 11.8% at 5 [11.9%],
// 11.6% at 6 [11.7%] (groups of faces, one light standing for the sun and a sixth of the sky: the
// +Z plane sees that sky, not the sun), 2.6% at 7–10, 1.26% at 11–12, and within 1% from 13 on:
// 0.68% at 16 [0.53%], 0.02% at 32 [1.11%], 0.03% at 64 [0.35%] (Eq. (9)'s centroid: 35 of the 256
// counts over 1%, up to 2.0% at 21). Asserted: 1% from 13 lights on, 1.5x the measured error
// below.
TEST(Environment, AreaLightsKeepThePlanesIrradianceForEveryCount) {
  const std::map<int, double> measured = {{1, 0.760},  {2, 0.447},   {3, 0.190},   {4, 0.0516},
                                          {5, 0.119},  {6, 0.117},   {7, 0.0261},  {8, 0.0261},
                                          {9, 0.0261}, {10, 0.0261}, {11, 0.0127}, {12, 0.0127}};
  expect_sky_plane_energy(1, false, [&](int count) -> std::optional<double> {
    if (auto it = measured.find(count); it != measured.end()) return 1.5 * it->second;
    return std::nullopt;
  });
}

// The same check with the horizon split (median_cut's horizon_split, "horizon_split": true: no
// region across the horizon y = 0), N = 10 (the fewest it makes) to 256. Measured, worst over the
// three normals (before, with Eq. (9)'s centroid, in brackets): 12.4% at 10 lights [13.1%], 3.4%
// at 11–14, 2.06% at 15–16 [2.65%], 2.13% at 17, 1.51% at 18, 1.13% at 19 (the +Z plane, whose
// horizon the split does not follow), within 1% from 20 on (0.02% at 32 [0.90%]). Asserted: the
// issue's 1% from 20 lights on, 1.5x the measured error below.
TEST(Environment, AreaLightsKeepThePlanesIrradianceWithTheHorizonSplit) {
  const std::map<int, double> measured = {{10, 0.125},  {11, 0.0341}, {12, 0.0341}, {13, 0.0341}, {14, 0.0341},
                                          {15, 0.0207}, {16, 0.0207}, {17, 0.0213}, {18, 0.0151}, {19, 0.0114}};
  expect_sky_plane_energy(10, true, [&](int count) -> std::optional<double> {
    if (auto it = measured.find(count); it != measured.end()) return 1.5 * it->second;
    return std::nullopt;
  });
}

// Sub-lights ("sub_lights": 64): each light's unshadowed irradiance the sum of the 64-region cut's
// lights in its region. The issue's energy check at every count 1–256 on the sky (the three normals
// above), without the exceptions below 13 lights: within 1%, the error being that of the 64-region
// cut for every count below 64 (measured: 0.03% worst) and the count's own from 64 on.
TEST(Environment, SubLightsKeepThePlanesIrradianceForEveryCount) {
  static const msm::probe::CubeMap cube = msm::probe::load_probe("sky", 32);
  double worst = 0.0;
  for (int count = 1; count <= 256; ++count) {
    const std::string json = R"({"msm_scene": 1, "probe": {"file": "sky", "size": 32, "sub_lights": 64, "lights": )" +
                             std::to_string(count) +
                             R"(}, "objects": [{"primitive": {"type": "plane", "size": [4, 4]}}]})";
    const Scene scene = msm::scene::load_scene_json(json, std::filesystem::current_path(), "t.json");
    ASSERT_EQ(scene.lights.front().sub_lights.empty(), count >= 64) << count;
    for (const glm::dvec3& n : kPlaneNormals) {
      const double error = std::abs(plane_energy_error_with_sub_lights(scene, scene.lights, cube, n));
      worst = std::max(worst, error);
      EXPECT_LT(error, 0.01) << count << " lights, n = " << n.x << ", " << n.y << ", " << n.z;
    }
  }
  std::printf("[energy] sky with 64 sub-lights, 1 to 256 lights: worst relative error %.4f\n", worst);
}

// The energy check on the eight studio probes at 32² faces for the counts [first, last], five
// normals (kPlaneNormals, −X and (0, 1, −1)), lights_of(tables, count) as the scene makes them
// (with their sub-lights where they have them): within the issue's 1%; the worst error printed.
template <class LightsOf>
void expect_studio_plane_energy(int first, int last, const char* what, LightsOf lights_of) {
  const Scene frame = sky_scene(kTopCamera, kPlane);
  for (const char* name : {"city", "courtyard", "forest", "interior", "night", "studio", "sunrise", "sunset"}) {
    const msm::probe::CubeMap cube =
        msm::probe::load_probe(std::string(MSM_STUDIOLIGHTS_DIR) + "/" + name + ".exr", 32);
    const msm::probe::ProbeTables tables(cube);
    double worst = 0.0;
    for (int count = first; count <= last; ++count) {
      const std::vector<msm::scene::DirectionalLight> lights = lights_of(tables, count);
      for (const glm::dvec3& n : {kPlaneNormals[0], kPlaneNormals[1], kPlaneNormals[2], glm::dvec3(-1, 0, 0),
                                  glm::normalize(glm::dvec3(0, 1, -1))}) {
        const double error = std::abs(plane_energy_error_with_sub_lights(frame, lights, cube, n));
        worst = std::max(worst, error);
        EXPECT_LT(error, 0.01) << name << ", " << count << " lights, n = " << n.x << ", " << n.y << ", " << n.z;
      }
    }
    std::printf("[energy] %s.exr, %s, %d to %d lights: worst relative error %.4f\n", name, what, first, last, worst);
  }
}

// The same check on real probes: the eight CC0 studio lights of blender-data, the CPU cut's
// lights. Measured: within 1% at every count from 62 on for all eight (the last over 1%: studio 61
// lights, 1.45%); at 16–61 lights up to 6% (studio), regions that straddle a plane's horizon being
// uniform rectangles where the probe is not: 300 of the 8 x 256 (probe, count) cases over 1%
// (with Eq. (9)'s centroid: 414, the last at 83 lights, city). Asserted: 1% from 64 lights
// on.
TEST(Environment, AreaLightsKeepTheStudioProbesIrradianceFromSixtyFourLights) {
  expect_studio_plane_energy(64, 256, "no sub-lights", [](const msm::probe::ProbeTables& tables, int count) {
    std::vector<msm::scene::DirectionalLight> lights;
    for (const auto& a : msm::probe::area_lights(tables, msm::probe::median_cut(tables, count)))
      lights.push_back(msm::scene::light_of_area_light(a));
    return lights;
  });
}

// Sub-lights on the studio probes: with 64 sub-lights every count from 1 to 63 gets the 64-region
// cut's unshadowed irradiance (from 64 on the lights are that cut's own: the test above), within
// 1% on all eight probes, where without them 300 of the 8 x 256 cases were over 1% (up to 76% at
// one light). Measured: worst 0.90% (studio, the 64-region cut's own error).
TEST(Environment, SubLightsKeepTheStudioProbesIrradianceForEveryCount) {
  expect_studio_plane_energy(1, 63, "64 sub-lights", [](const msm::probe::ProbeTables& tables, int count) {
    std::vector<msm::scene::DirectionalLight> lights;
    for (const msm::probe::ProbeLight& pl : msm::probe::lights_with_sub_lights(tables, count, 64))
      lights.push_back(msm::scene::light_of_probe_light(pl));
    return lights;
  });
}

} // namespace
