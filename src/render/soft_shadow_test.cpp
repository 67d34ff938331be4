// Soft shadows in the renderer against the ray-traced area light (msm::reference, effect soft):
// moment soft shadows with four and six moments (JCGT §4, Kneiphof §4.2, include/msm/soft.h with
// the integer summed-area tables of msm::gpu) and their baselines, naive variance soft shadows and
// percentage-closer soft shadows with a 15² search. Error figures go to docs/results.md.
#include "msm/light_probe.h"
#include "msm/reference/analytic.h"
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/shading.h"
#include "msm/techniques.h"

#include "msm/image/metrics.h"
#include "msm/test/figures.h"
#include "msm/test/image_compare.h"
#include "msm/test/reference_settings.h"
#include "msm/test/render_settings.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace msm::render {
namespace {

class SoftShadowTest : public vk::test::VulkanTest {};

const std::vector<std::string> kSoftTechniques = {"mssm4", "mssm6", "vssm", "pcss"};

// The ray-traced soft shadow of the scene's light (its own extent where extent_deg is empty, its
// own shape where shape is).
reference::Result area_light_truth(const scene::Scene& scene, int width, int height, std::optional<double> extent_deg,
                                   int samples = 64, std::optional<reference::LightShape> shape = std::nullopt) {
  reference::Settings rs = test::reference_settings(reference::Effect::soft, width, height, samples);
  rs.light_shape = shape;
  rs.light_extent_deg = extent_deg;
  return reference::render(scene, rs);
}

RenderSettings soft_settings(const std::string& technique, int width, int height, float extent_deg,
                             int shadow_size = 512) {
  RenderSettings s = test::render_settings(technique, width, height, shadow_size);
  s.light_extent_deg = extent_deg;
  return s;
}

// Error of each technique's visibility against the ray-traced area light (background excluded).
// The map is fitted to the whole scene ("fit_scene"): these tests size kernels in texels of it.
std::map<std::string, image::Metrics> errors(const vk::Context& ctx, scene::Scene scene, float extent_deg,
                                             const std::vector<std::string>& techniques, int shadow_size = 512,
                                             int width = 240, int height = 135) {
  scene.shadow.mode = scene::ShadowFraming::Mode::fit_scene;
  reference::Result truth = area_light_truth(scene, width, height, extent_deg);
  image::Image mask = truth.visibility.channel("background");
  Renderer renderer(ctx, scene);
  std::map<std::string, image::Metrics> out;
  for (const std::string& t : techniques) {
    image::Image v =
        renderer.render(soft_settings(t, width, height, extent_deg, shadow_size)).shadow.channel("visibility");
    out[t] = image::compute_metrics(v, truth.visibility.channel("visibility"), {.mask = &mask});
    EXPECT_EQ(out[t].non_finite, 0u) << t;
    fmt::print("{} {}°: {:<16} MAE {:.4f}, leaking {:.4f}, over-darkening {:.4f}, >10% {:.2f}%\n", scene.name,
               extent_deg, t, out[t].mae, out[t].light_leaking, out[t].over_darkening, 100 * out[t].share_above_10pct);
  }
  return out;
}

// The MAE of each soft technique against the ray-traced area light, per scene and light size, as
// measured on lavapipe (docs/results.md, "Soft shadows in the renderer"): the column and the fence
// under 3°, the models (5°) and the pillar before the brick wall (4°) under their own lights.
// Re-measured with the least bias for the receiver's plane (msm_soft_plane_bias; "The least bias
// for the receiver's plane"): vssm 0.0034 -> 0.0019 (column), 0.0100 -> 0.0094 (fence), 0.0111 ->
// 0.0055 (pillar_wall), mssm4 0.0078 -> 0.0050 and mssm6 0.0061 -> 0.0046 (pillar_wall); the rest
// within 0.0002 of a run just before the change (which had itself drifted from this
// table's older values by up to +0.0003: column mssm4 0.0015, mssm6 0.0008, models mssm6 0.0041).
const std::map<std::string, std::map<std::string, double>> kMeasuredSoftMae = {
    {"column", {{"mssm4", 0.0018}, {"mssm6", 0.0011}, {"vssm", 0.0019}, {"pcss", 0.0015}}},
    {"fence", {{"mssm4", 0.0062}, {"mssm6", 0.0053}, {"vssm", 0.0094}, {"pcss", 0.0076}}},
    {"models", {{"mssm4", 0.0052}, {"mssm6", 0.0044}, {"vssm", 0.0073}, {"pcss", 0.0060}}},
    {"pillar_wall", {{"mssm4", 0.0050}, {"mssm6", 0.0046}, {"vssm", 0.0055}, {"pcss", 0.0033}}},
};

// The bound: 1.5x the measured MAE, and at least +0.002 (the reference's Monte Carlo noise).
void expect_near_measured(const std::string& scene, const std::string& technique, double mae) {
  const double measured = kMeasuredSoftMae.at(scene).at(technique);
  EXPECT_LE(mae, std::max(1.5 * measured, measured + 0.002))
      << scene << ", " << technique << " (measured " << measured << ")";
  msm::test::record_figure("ground_truth.soft." + scene + "." + technique + ".mae", mae,
                           {.below = std::max(1.5 * measured, measured + 0.002),
                            .meaning = scene + ", " + technique + ": MAE of visibility against the traced area light"});
}

// On the column (JCGT Fig. 11: a long shadow, so its penumbra grows from contact to wide) and the
// fence, lit by a disc light of 3 degrees: every soft technique is closer to the ray-traced soft
// shadow than the hard shadows, and within the bound of its measured error.
TEST_F(SoftShadowTest, CloserToTheAreaLightThanHardShadows) {
  for (const char* name : {"column", "fence"}) {
    std::vector<std::string> techniques = kSoftTechniques;
    techniques.push_back("msm-hamburger-64");
    techniques.push_back("pcf");
    auto m = errors(ctx(), scene::builtin_scene(name), 3.0f, techniques);
    for (const std::string& t : kSoftTechniques) {
      EXPECT_LT(m[t].mae, m["msm-hamburger-64"].mae) << name << ", " << t;
      EXPECT_LT(m[t].mae, m["pcf"].mae) << name << ", " << t;
      expect_near_measured(name, t, m[t].mae);
    }
  }
}

// JCGT Fig. 11: on long-range shadows the 27² search of moment soft shadows still finds the
// blockers whose penumbrae reach the fragment, where PCSS's 15² search (225 taps) falls short and
// leaks light in the outer penumbra. The column at 80° incidence under a 10° light: penumbrae up
// to ~40 texels wide in a 512² map.
TEST_F(SoftShadowTest, LongRangeShadowsMssmBeatsPcssWith15x15Search) {
  auto m = errors(ctx(), scene::builtin_scene("column"), 10.0f, kSoftTechniques);
  EXPECT_LT(m["mssm4"].mae, m["pcss"].mae);
  EXPECT_LT(m["mssm6"].mae, m["pcss"].mae);
  EXPECT_LT(m["mssm4"].light_leaking, m["pcss"].light_leaking);
}

// Kneiphof §4.2: six moments reconstruct the depth distribution of large search regions better
// (four nodes instead of three), so MSSM6 leaks less light than MSSM4 under large lights, where the
// regions hold several occluders (the fence's sign, bars and wall under a 10° light: 0.0052
// against 0.0071), and its error is lower on both scenes. The column (one occluder) leaks alike
// since each takes the least bias its bound needs for the receiver's plane (soft.h), more for six
// moments than for four: 0.00467 against 0.00460 (before, with the same worst-case bias for both,
// 0.0049 against 0.0051); its leaking is not compared.
TEST_F(SoftShadowTest, SixMomentsLeakLessThanFourOnLargeLights) {
  for (const char* name : {"fence", "column"}) {
    auto m = errors(ctx(), scene::builtin_scene(name), 10.0f, {"mssm4", "mssm6"});
    if (std::string(name) == "fence") { EXPECT_LT(m["mssm6"].light_leaking, m["mssm4"].light_leaking) << name; }
    EXPECT_LT(m["mssm6"].mae, m["mssm4"].mae) << name;
  }
}

// Kneiphof §4.2.2, Eq. (19): counting the mass the moments allow at the receiver into the average
// blocker depth (clamped to [δ1, δ2]) moves the blockers towards the receiver where the moments
// are unsure, which narrows the penumbra there: less light leaks than with JCGT Eq. (4) on the same
// six-moment tables (`--param 0.001 0.001 0 0`), for every light of the frame (the parameters are
// the frame's). Under a 10° light, 240x135, 512², measured on lavapipe: the fence (sign, bars and
// wall in one search region: where it matters) leaks 0.00584 against 0.00674 (ratio 0.87; MAE
// 0.00777 against 0.00839), bound 0.95; the column (one occluder: Eq. (4) is exact already) leaks
// the same 0.00489 with both (MAE 0.00746 against 0.00784), bound: no more than 2% above Eq. (4).
TEST_F(SoftShadowTest, UpperBoundBlockerDepthLeaksLessThanEquation4) {
  for (const char* name : {"fence", "column"}) {
    scene::Scene scene = scene::builtin_scene(name);
    scene.shadow.mode = scene::ShadowFraming::Mode::fit_scene;
    const int width = 240, height = 135;
    reference::Result truth = area_light_truth(scene, width, height, 10.0);
    image::Image mask = truth.visibility.channel("background");
    Renderer renderer(ctx(), scene);
    auto measure = [&](ParameterValues parameters) {
      RenderSettings s = soft_settings("mssm6", width, height, 10.0f);
      s.parameters = parameters;
      image::Image v = renderer.render(s).shadow.channel("visibility");
      return image::compute_metrics(v, truth.visibility.channel("visibility"), {.mask = &mask});
    };
    image::Metrics eq19 = measure({}), eq4 = measure({{"delta2", MSM_BLOCKER_EPSILON}, {"blocker_estimate", 0.0f}});
    fmt::print("{} 10°: mssm6 light leaking Eq. (19) {:.5f}, Eq. (4) {:.5f} (ratio {:.2f}); MAE {:.5f}, {:.5f}\n", name,
               eq19.light_leaking, eq4.light_leaking, eq19.light_leaking / eq4.light_leaking, eq19.mae, eq4.mae);
    const bool fence = std::string(name) == "fence";
    EXPECT_LT(eq19.light_leaking, (fence ? 0.95 : 1.02) * eq4.light_leaking) << name;
    EXPECT_LT(eq19.mae, eq4.mae) << name;
  }
}

// Convolution soft shadow maps (Annen et al. 2008; cssm.h), Kneiphof's baseline, against the
// ray-traced area light: the column and the fence under 3°, the models under their own 5°, 240x135,
// 512². Measured on lavapipe (MAE, nearly all of it light leaking: CSM's scaled series is a lower
// bound, baselines.h); bound as expect_near_measured. More frequencies leak less: cssm16 <= cssm8
// on every scene; and moment soft shadows (mssm4: 0.0019, 0.0063, 0.0053) beat both. Measured with
// the basis on 3/4 of the depth range (baselines.h, MSM_CSM_BASIS_RANGE; before: 0.0112 / 0.0083,
// 0.0177 / 0.0143, 0.0185 / 0.0113).
const std::map<std::string, std::map<std::string, double>> kMeasuredCssmMae = {
    {"column", {{"cssm8", 0.0127}, {"cssm16", 0.0087}}},
    {"fence", {{"cssm8", 0.0195}, {"cssm16", 0.0148}}},
    {"models", {{"cssm8", 0.0209}, {"cssm16", 0.0132}}},
};

TEST_F(SoftShadowTest, ConvolutionSoftShadowMaps) {
  for (const auto& [name, measured] : kMeasuredCssmMae) {
    scene::Scene scene = scene::builtin_scene(name);
    const float extent = name == "models" ? scene.light().angular_extent_deg : 3.0f;
    auto m = errors(ctx(), scene, extent, {"cssm8", "cssm16", "mssm4", "pcss"});
    for (const char* t : {"cssm8", "cssm16"}) {
      const double bound = std::max(1.5 * measured.at(t), measured.at(t) + 0.002);
      EXPECT_LE(m[t].mae, bound) << name << ", " << t << " (measured " << measured.at(t) << ")";
      msm::test::record_figure("ground_truth.soft." + name + "." + t + ".mae", m[t].mae,
                               {.below = bound, .meaning = "MAE of visibility against the traced area light"});
    }
    EXPECT_LE(m["cssm16"].mae, m["cssm8"].mae) << name;
    EXPECT_LT(m["mssm4"].mae, m["cssm16"].mae) << name;
  }
}

// No light extent: the penumbra shrinks to the minimum kernel (half a texel: a bilinear lookup),
// so every soft technique becomes a hard shadow close to the 1-tap PCF.
TEST_F(SoftShadowTest, ZeroExtentGivesHardShadows) {
  Renderer renderer(ctx(), scene::builtin_scene("fence"));
  RenderSettings s = soft_settings("pcf", 240, 135, 0.0f);
  s.filter_size = 1;
  RenderResult hard = renderer.render(s);
  image::Image mask = hard.shadow.channel("background");
  for (const std::string& t : kSoftTechniques) {
    image::Image soft = renderer.render(soft_settings(t, 240, 135, 0.0f)).shadow.channel("visibility");
    image::Metrics m = image::compute_metrics(soft, hard.shadow.channel("visibility"), {.mask = &mask});
    fmt::print("fence, extent 0: {} against 1-tap PCF: MAE {:.4f}, >10% {:.2f}%\n", t, m.mae,
               100 * m.share_above_10pct);
    EXPECT_LT(m.mae, 0.02) << t;
  }
}

// JCGT Fig. 8 (two models above a plane: penumbrae from contact-hard to wide) and Fig. 10 (a
// pillar before a brick wall: its penumbra fuses with the bricks' short shadows), under the
// scenes' own lights (5° and 4°), at 240x135. The bricks stand 2 cm proud of the mortar: with a
// 512² map (2.3 cm texels) the depth bias that grows with the filter (soft.h) swallowed their
// shadows (MAE 0.07 for mssm4 with JCGT's worst-case bias, 0.007 for PCSS, which tests every
// sample against the exact receiver plane); the wall is rendered with a 2048² map, where the
// relief spans a few texels.
TEST_F(SoftShadowTest, ModelsAndPillarBeforeBrickWall) {
  for (const char* name : {"models", "pillar_wall"}) {
    scene::Scene scene = scene::builtin_scene(name);
    bool wall = std::string(name) == "pillar_wall";
    auto m = errors(ctx(), scene, scene.light().angular_extent_deg, kSoftTechniques, wall ? 2048 : 512);
    for (const std::string& t : kSoftTechniques) expect_near_measured(name, t, m[t].mae);
    EXPECT_LT(m["mssm4"].mae, m["vssm"].mae) << name;
    EXPECT_LT(m["mssm6"].mae, m["vssm"].mae) << name;
  }
}

// The analytic soft shadow: the built-in disc scene (a thin disc 1 m above the ground, light
// straight down) against msm::reference::disc_occluder_visibility at every pixel's ground point,
// with a 4° light and a 256² map (penumbra 12 texels wide: inside every technique's kernel).
TEST_F(SoftShadowTest, DiscSceneAgainstTheAnalyticSoftShadow) {
  scene::Scene scene = scene::builtin_scene("disc");
  const int width = 160, height = 90;
  const float extent = 4.0f;
  glm::dmat4 inverse = glm::inverse(glm::dmat4(scene.camera_view_projection(float(width) / float(height))));
  image::Image truth(width, height, 1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      glm::dvec2 ndc((x + 0.5) / width * 2 - 1, (y + 0.5) / height * 2 - 1);
      glm::dvec4 a = inverse * glm::dvec4(ndc, 0.0, 1.0), b = inverse * glm::dvec4(ndc, 1.0, 1.0);
      glm::dvec3 from = glm::dvec3(a) / a.w, to = glm::dvec3(b) / b.w;
      glm::dvec3 ground = from + (to - from) * (from.y / (from.y - to.y));
      truth.at(x, y, 0) = float(reference::disc_occluder_visibility(ground, extent));
    }
  Renderer renderer(ctx(), scene);
  for (const std::string& t : kSoftTechniques) {
    RenderSettings s = soft_settings(t, width, height, extent);
    s.shadow_size = 256;
    image::Image v = renderer.render(s).shadow.channel("visibility");
    // Measured MAE: 0.002-0.006; bound 0.01, and no pixel off by more than 0.25 (the nine-region
    // filter's box is not the disc light's profile: the penumbra's shape differs a little).
    image::CompareResult c = image::compare(v, truth, {.max_mae = 0.01, .max_error = 0.25, .max_share_above_3pct = 1.0},
                                            {.failure_dir = "test-failures/soft/disc-" + t});
    fmt::print("disc {}°: {:<6} against the analytic visibility: MAE {:.4f}, max {:.3f}, leaking {:.4f}\n", extent, t,
               c.metrics.mae, c.metrics.max_error, c.metrics.light_leaking);
    EXPECT_TRUE(c.passed) << t << ": " << c.report;
  }
}

// ---- Horizon-aware shading of area lights ----
// A plane under a light of 60° (cone half-angle α = 30°) whose axis is `elevation_deg` above the
// plane: at 10° a third of the cone lies below the horizon, at -10° most of it, so Eq. (15)'s
// π sin² α cos no longer holds. The ray tracer integrates max(n·d, 0) V over the cone by sampling
// (reference.h, effect soft); the renderer's area-light techniques use msm_cone_cosine, the hard
// techniques (point lights) max(n·l, 0), which is 0 at -10°.
scene::Scene horizon_scene(float elevation_deg) {
  const float e = glm::radians(elevation_deg);
  return scene::load_scene_json(fmt::format(R"({{ "msm_scene": 1, "name": "horizon",
      "camera": {{ "position": [0, 4, -6], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40 }},
      "light": {{ "towards_light": [0, {}, {}], "irradiance": [2, 2, 2], "angular_extent_deg": 60 }},
      "objects": [ {{ "name": "ground", "primitive": {{ "type": "plane", "size": [8, 8] }},
                      "material": {{ "albedo": [0.5, 0.5, 0.5] }} }} ] }})",
                                            std::sin(e), std::cos(e)),
                                ".", "horizon");
}

// Mean relative error of the renderer's radiance (its displayed colour through msm_aces_inverse)
// against the ray tracer's over the covered pixels.
double radiance_error(const image::Image& color, const image::Image& truth, const image::Image& background) {
  double sum = 0.0;
  int n = 0;
  for (int y = 0; y < color.height(); ++y)
    for (int x = 0; x < color.width(); ++x) {
      if (background.at(x, y, 0) > 0.5f) continue;
      const double got = msm_aces_inverse(color.at(x, y, 1)), want = truth.at(x, y, 1);
      sum += std::abs(got - want) / want;
      ++n;
    }
  return n ? sum / n : 1.0;
}

// Measured (lavapipe): mssm4, mssm6 and pcss 0.64% (10°) and 1.09% (-10°) from the ray tracer; the
// point shading of msm-hamburger-64 17.7% and 47.9% (ambient only). Bound: 2% (8-bit colour,
// Monte Carlo noise of 256 samples); the point shading must be off by more than 10%.
TEST_F(SoftShadowTest, AreaLightBelowTheHorizonMatchesTheRayTracer) {
  for (float elevation : {10.0f, -10.0f}) {
    scene::Scene scene = horizon_scene(elevation);
    const int width = 160, height = 90;
    reference::Result truth = area_light_truth(scene, width, height, std::nullopt, 256);
    image::Image background = truth.visibility.channel("background");
    Renderer renderer(ctx(), scene);
    for (const std::string t : {"mssm4", "mssm6", "pcss", "msm-hamburger-64"}) {
      RenderSettings s = soft_settings(t, width, height, 60.0f, 256);
      const double error = radiance_error(renderer.render(s).color, truth.radiance, background);
      fmt::print("horizon, light {}° above the plane, 60° wide: {:<16} radiance {:.2f}% from the ray tracer\n",
                 elevation, t, 100.0 * error);
      if (t == "msm-hamburger-64")
        EXPECT_GT(error, 0.1) << elevation;
      else
        EXPECT_LT(error, 0.02) << t << " at " << elevation;
    }
  }
}

// A plane under a rectangular light 80° wide and 30° high whose centre is `elevation_deg` above
// the plane, its width along the horizon (x_axis [1, 0, 0]) or turned 45° about its direction, so
// that the horizon cuts it through two opposite edges or across a corner. The renderer's
// area-light techniques shade it by msm_rect_light_cosine (the rectangle clipped by the horizon);
// the ray tracer (effect soft, rectangle) samples the rectangle on the same frame axes.
scene::Scene rectangle_horizon_scene(float elevation_deg, bool turned) {
  const float e = glm::radians(elevation_deg);
  const glm::vec3 l(0.0f, std::sin(e), std::cos(e));
  const glm::vec3 x = turned ? glm::normalize(glm::vec3(1.0f, 0.0f, 0.0f) + glm::cross(l, glm::vec3(1.0f, 0.0f, 0.0f)))
                             : glm::vec3(1.0f, 0.0f, 0.0f);
  return scene::load_scene_json(fmt::format(R"({{ "msm_scene": 1, "name": "rectangle_horizon",
      "camera": {{ "position": [0, 4, -6], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40 }},
      "light": {{ "towards_light": [0, {}, {}], "irradiance": [2, 2, 2], "angular_extent_deg": 80,
                  "angular_height_deg": 30, "x_axis": [{}, {}, {}] }},
      "objects": [ {{ "name": "ground", "primitive": {{ "type": "plane", "size": [8, 8] }},
                      "material": {{ "albedo": [0.5, 0.5, 0.5] }} }} ] }})",
                                            l.y, l.z, x.x, x.y, x.z),
                                ".", "rectangle_horizon");
}

// Measured (lavapipe), mssm4's radiance against the ray tracer (256 samples): 0.47%, 0.33%, 1.37%
// at 10°, 0°, -8° along the horizon, 0.61%, 0.64%, 1.37% turned. Bound: 2% (8-bit colour, Monte
// Carlo noise), as for the disc above. The cone of the rectangle's solid angle (msm_cone_cosine,
// the shading before) gives factors off by +14.7%, +55%, +210% and -10.4%, -21.7%, -36.5%; its
// radiance (ambient included) must differ by more than 5%, or the test could not tell the two
// apart. (pcss, not asserted: 1.48% and 2.05% at 10° and -8° turned, with the same shading factor:
// its shadow on the unoccluded plane, cause not isolated.)
TEST_F(SoftShadowTest, RectangularLightAcrossTheHorizonMatchesTheRayTracer) {
  for (bool turned : {false, true})
    for (float elevation : {10.0f, 0.0f, -8.0f}) {
      scene::Scene scene = rectangle_horizon_scene(elevation, turned);
      const scene::DirectionalLight& light = scene.light();
      const glm::vec3 n(0.0f, 1.0f, 0.0f);
      const float rect = msm_light_cosine(n, light.towards_light, glm::vec3(scene.light_frame(light).x_axis),
                                          light.rectangle_extents(), light.cone_half_angle());
      const float cone = msm_cone_cosine(light.towards_light.y, light.cone_half_angle());
      const int width = 160, height = 90;
      reference::Result truth =
          area_light_truth(scene, width, height, std::nullopt, 256, reference::LightShape::rectangle);
      image::Image background = truth.visibility.channel("background");
      Renderer renderer(ctx(), scene);
      const auto radiance = [](float factor) {
        return msm_surface_radiance(vec3(0.5f), msm_direct_light(vec3(2.0f), factor, vec3(1.0f)), MSM_AMBIENT).y;
      };
      EXPECT_GT(std::abs(radiance(cone) / radiance(rect) - 1.0f), 0.05f) << elevation << (turned ? " turned" : "");
      for (const std::string t : {"mssm4"}) {
        RenderSettings s;
        s.technique = t;
        s.width = width;
        s.height = height;
        s.shadow_size = 256;
        const double error = radiance_error(renderer.render(s).color, truth.radiance, background);
        fmt::print("rectangle 80° x 30°{}, centre {}° above the plane: {:<6} radiance {:.2f}% from the ray tracer; "
                   "factor {:.4f}, the cone's {:.4f} ({:+.1f}%)\n",
                   turned ? " turned 45°" : "", elevation, t, 100.0 * error, rect, cone, 100.0 * (cone / rect - 1.0));
        EXPECT_LT(error, 0.02) << t << " at " << elevation << (turned ? " turned" : "");
      }
    }
}

// ---- Contact hardening, measured ----
// A plank 1 m wide rising from the ground (x = -3) to 2 m (x = 3) under a 6° light from 45°
// elevation in the y-z plane; the camera looks straight down beside it. The shadow of the
// plank's side edge at height h falls at z = -0.5 - h, with a penumbra that grows linearly with h
// (width 4 tan(3°) h on the ground: 0.2 m at h = 1). The width of the transition (visibility in
// (0.1, 0.9)) is counted along image columns at several h.
scene::Scene plank_scene() {
  return scene::load_scene_json(R"({ "msm_scene": 1, "name": "plank",
      "camera": { "position": [0, 6, -1.5], "target": [0, 0, -1.5], "up": [0, 0, -1], "fov_y_deg": 40 },
      "light": { "towards_light": [0, 0.70710678, 0.70710678], "angular_extent_deg": 6 },
      "shadow_map": { "framing": "fit_scene" },
      "objects": [
        { "name": "ground", "primitive": { "type": "plane", "size": [9, 9] }, "transform": { "translate": [0, 0, -1.5] } },
        { "name": "plank", "primitive": { "type": "box", "size": [6.3246, 0.02, 1.0] },
          "transform": { "translate": [0, 1.0, 0], "rotate": [0, 0, 18.4349] } } ] })",
                                ".", "plank");
}

// The 10%-90% width of the penumbra in metres on the ground at each height of the plank's edge:
// along three neighbouring image columns, from outside the shadow towards the middle of the strip,
// the first crossings of visibility 0.9 and 0.1, interpolated between pixels, averaged.
std::vector<double> penumbra_widths(const scene::Scene& scene, const image::Image& visibility,
                                    const std::vector<double>& heights) {
  int w = visibility.width(), h = visibility.height();
  glm::mat4 vp = scene.camera_view_projection(float(w) / float(h));
  auto row_of = [&](glm::vec3 p) {
    glm::vec4 c = vp * glm::vec4(p, 1.0f);
    return glm::vec2((c.x / c.w * 0.5f + 0.5f) * float(w), (c.y / c.w * 0.5f + 0.5f) * float(h) - 0.5f);
  };
  std::vector<double> out;
  for (double height : heights) {
    float x = float(3.0 * height - 3.0);
    glm::vec2 far = row_of({x, 0.0f, -0.5f - float(height) - 0.8f});
    glm::vec2 near = row_of({x, 0.0f, std::min(-float(height), -0.55f)});
    double metres_per_row = 1.0 / double(std::abs(row_of({x, 0.0f, 0.0f}).y - row_of({x, 0.0f, 1.0f}).y));
    int step = near.y > far.y ? 1 : -1;
    double sum = 0;
    for (int dx = -1; dx <= 1; ++dx) {
      int column = std::clamp(int(far.x) + dx, 0, w - 1);
      auto crossing = [&](float level) { // first row (fractional) where visibility drops below level
        int y0 = std::clamp(int(std::lround(far.y)), 0, h - 1), y1 = std::clamp(int(std::lround(near.y)), 0, h - 1);
        for (int y = y0; y != y1; y += step) {
          float a = visibility.at(column, y, 0), b = visibility.at(column, y + step, 0);
          if (a >= level && b < level) return double(y) + step * double(a - level) / double(a - b);
        }
        return double(y1);
      };
      sum += std::abs(crossing(0.1f) - crossing(0.9f));
    }
    out.push_back(sum / 3.0 * metres_per_row);
  }
  return out;
}

TEST_F(SoftShadowTest, PenumbraeWidenWithReceiverDistance) {
  scene::Scene scene = plank_scene();
  const std::vector<double> heights = {0.4, 0.8, 1.2, 1.6};
  const int width = 480, height = 270;
  reference::Result truth = area_light_truth(scene, width, height, 6.0);
  std::vector<double> expected = penumbra_widths(scene, truth.visibility, heights);
  fmt::print("penumbra width (m) at h = 0.4, 0.8, 1.2, 1.6: ray traced {:.3f} {:.3f} {:.3f} {:.3f}\n", expected[0],
             expected[1], expected[2], expected[3]);
  // The ray tracer: a straight edge covers 10% of the light's disc at 0.687 of its radius from
  // the centre, so the 10%-90% width is 0.687 of the full width 4 tan(3°) h.
  for (size_t i = 0; i < heights.size(); ++i)
    EXPECT_NEAR(expected[i], 0.687 * 4 * std::tan(glm::radians(3.0)) * heights[i], 0.01) << "h = " << heights[i];
  Renderer renderer(ctx(), scene);
  for (std::string t : {"mssm4", "mssm6", "vssm", "pcss", "msm-hamburger-64"}) {
    std::vector<double> got = penumbra_widths(
        scene, renderer.render(soft_settings(t, width, height, 6.0f)).shadow.channel("visibility"), heights);
    fmt::print("penumbra width (m) at h = 0.4, 0.8, 1.2, 1.6: {:<16} {:.3f} {:.3f} {:.3f} {:.3f}\n", t, got[0], got[1],
               got[2], got[3]);
    if (t == "msm-hamburger-64") {
      // A hard shadow with a fixed 9² filter: the same width everywhere.
      EXPECT_LT(got[3], 1.5 * got[0] + 0.01);
      continue;
    }
    // Contact hardening: four times the height, at least three times the width (ray traced: 4.0);
    // each width within 30% (plus 3 cm, ~2 pixels) of the ray-traced one. PCSS's 15-texel kernel
    // (~0.3 m here) caps its penumbra: at h = 1.6 it falls short by more than 10% (JCGT's reason
    // for a 27² search), so it is held to the tolerance up to h = 1.2 only.
    bool pcss = t == "pcss";
    if (!pcss)
      EXPECT_GT(got[3], 3.0 * got[0]) << t;
    else
      EXPECT_GT(got[2], 2.0 * got[0]) << t;
    for (size_t i = 0; i < heights.size(); ++i) {
      if (pcss && heights[i] > 1.3) {
        EXPECT_LT(got[i], 0.9 * expected[i]) << "pcss at h = " << heights[i];
        continue;
      }
      EXPECT_NEAR(got[i], expected[i], 0.3 * expected[i] + 0.03) << t << " at h = " << heights[i];
    }
  }
}

// ---- Rectangular area lights (Kneiphof §4.1.2): two extents, two spreads ----
// A thin plate (a plane, both faces in the map) over the quadrant x < 0, z < 0 at height 1.5 over
// the ground, lit from straight above by a rectangle 20° wide along its x_axis = +Z and 8° high
// along the frame's other axis (X). The camera looks straight down from under the plate. A straight
// edge at height h under a light uniform on its plane at unit distance casts a linear ramp whose
// full width is 2 h tan(θ/2) along the axis across the edge: 3 tan(10°) = 0.529 m behind the edge
// z = 0 (across the light's width), 3 tan(4°) = 0.210 m behind the edge x = 0 (across its height),
// in the ratio tan(10°) / tan(4°) = 2.52. The width is read as twice the distance between the
// crossings of visibility 0.75 and 0.25 (half the ramp), of the range from the umbra to the lit
// side as measured (CSSM leaks: its umbra is not 0). The fitted map's near plane is the plate, its
// far plane the ground (CssmShadowsReceiversOnTheFarPlane).
// probe: also a black probe (no light of its own), so that the environment effect draws the light.
scene::Scene rectangle_edge_scene(bool probe = false) {
  return scene::load_scene_json(
      std::string(R"({ "msm_scene": 1, "name": "rectangle_edge",)") +
          (probe ? R"("probe": { "file": "sky", "intensity": 0, "lights": 6, "size": 8 },)" : "") +
          R"(
  "camera": { "position": [0, 1.2, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov_y_deg": 90 },
      "light": { "towards_light": [0, 1, 0], "angular_extent_deg": 20, "angular_height_deg": 8, "x_axis": [0, 0, 1] },
      "shadow_map": { "framing": "fit_scene" },
      "objects": [
        { "name": "ground", "primitive": { "type": "plane", "size": [12, 12] } },
        { "name": "plate", "primitive": { "type": "plane", "size": [3, 3] }, "transform": { "translate": [-1.5, 1.5, -1.5] } } ] })",
      ".", "rectangle_edge");
}

// Bilinear sample of channel 0 at a world point on the ground (pixel centres at i + 0.5).
double sample_at(const scene::Scene& scene, const image::Image& v, glm::vec3 p) {
  const int w = v.width(), h = v.height();
  const glm::vec4 c = scene.camera_view_projection(float(w) / float(h)) * glm::vec4(p, 1.0f);
  const double x = (c.x / c.w * 0.5 + 0.5) * w - 0.5, y = (c.y / c.w * 0.5 + 0.5) * h - 0.5;
  const int x0 = std::clamp(int(std::floor(x)), 0, w - 2), y0 = std::clamp(int(std::floor(y)), 0, h - 2);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  return (1 - fy) * ((1 - fx) * v.at(x0, y0, 0) + fx * v.at(x0 + 1, y0, 0)) +
         fy * ((1 - fx) * v.at(x0, y0 + 1, 0) + fx * v.at(x0 + 1, y0 + 1, 0));
}

// Twice the distance from the 0.75 to the 0.25 crossing of visibility along lit -> dark (world
// points on the ground), averaged over three parallel lines `step` apart.
double ramp_width(const scene::Scene& scene, const image::Image& v, glm::vec3 lit, glm::vec3 dark, glm::vec3 step) {
  double sum = 0.0;
  for (int k = -1; k <= 1; ++k) {
    const glm::vec3 a = lit + float(k) * step, b = dark + float(k) * step;
    const int n = 600;
    const double top = sample_at(scene, v, a), bottom = sample_at(scene, v, b);
    const auto crossing = [&](double fraction) {
      const double level = bottom + fraction * (top - bottom);
      double prev = sample_at(scene, v, a);
      for (int i = 1; i <= n; ++i) {
        const double t = double(i) / n, cur = sample_at(scene, v, a + float(t) * (b - a));
        if (prev >= level && cur < level) return (t - (level - cur) / (prev - cur) / n) * double(glm::length(b - a));
        prev = cur;
      }
      return -1.0;
    };
    sum += 2.0 * (crossing(0.25) - crossing(0.75));
  }
  return sum / 3.0;
}

// The ramp of a straight edge at height h under the rectangle's directions (a, b) in
// [−t_across, t_across] x [−t_along, t_along] weighted by (1 + a² + b²)^−2, lit where the ray to
// (a, b) passes the edge: visibility V(s) = ∫_{a > −s/h} W(a) da / ∫ W, W(a) = ∫ (1 + a² + b²)^−2
// db (midpoint rule); returned as the same twice-the-quartile-distance as ramp_width.
double cosine_weighted_ramp(double h, double t_across, double t_along) {
  const int n = 4000, m = 200;
  std::vector<double> w(n);
  double total = 0.0;
  for (int i = 0; i < n; ++i) {
    const double a = -t_across + (i + 0.5) * 2.0 * t_across / n;
    for (int j = 0; j < m; ++j) {
      const double b = -t_along + (j + 0.5) * 2.0 * t_along / m;
      w[size_t(i)] += 1.0 / ((1.0 + a * a + b * b) * (1.0 + a * a + b * b));
    }
    total += w[size_t(i)];
  }
  const auto offset = [&](double level) { // s where V(s) = level
    double above = 0.0;
    for (int i = n - 1; i >= 0; --i) {
      const double next = above + w[size_t(i)] / total;
      if (next >= level) {
        const double a = -t_across + (i + (next - level) / (next - above)) * 2.0 * t_across / n;
        return -a * h;
      }
      above = next;
    }
    return t_across * h;
  };
  return 2.0 * (offset(0.75) - offset(0.25));
}

struct RampWidths {
  double across_width, across_height; // behind the edge z = 0 and the edge x = 0
};
RampWidths rectangle_ramps(const scene::Scene& scene, const image::Image& v) {
  return {ramp_width(scene, v, {-0.6f, 0.0f, 0.6f}, {-0.6f, 0.0f, -0.6f}, {0.1f, 0.0f, 0.0f}),
          ramp_width(scene, v, {0.5f, 0.0f, -0.6f}, {-0.5f, 0.0f, -0.6f}, {0.0f, 0.0f, 0.1f})};
}

// Each technique's ramp as a fraction of the hand-computed width, measured on lavapipe (the same
// along both axes; docs/results.md, "Rectangular area lights"): mssm4, vssm and pcss within 1.3%;
// mssm6 0.81 (Kneiphof Eq. 19's upper-bound blocker depth, harder when in doubt: the blocker
// placed nearer the receiver); cssm8 / cssm16 0.67 / 0.68 (CSM's blocker estimate). Asserted:
// each width within 5% of its technique's fraction, and the ratio of the two widths within 3% of
// tan(10°) / tan(4°) for every technique (measured within 0.4%).
const std::map<std::string, double> kRectangleRampFraction = {{"mssm4", 0.987}, {"mssm6", 0.808}, {"vssm", 0.989},
                                                              {"pcss", 0.999},  {"cssm8", 0.674}, {"cssm16", 0.680}};

// A penumbra's width (or the ratio of the two) against the one expected, with the relative tolerance
// asserted.
void record_ramp(const std::string& across, const std::string& who, double got, double expected, double tolerance) {
  msm::test::record_figure(
      "penumbra.rectangle." + across + "." + who + ".relative_error", std::abs(got / expected - 1.0),
      {.below = tolerance,
       .meaning = "a 20° x 8° rectangular light: the penumbra's width (or the ratio of the "
                  "two widths) against the hand-computed one (a renderer's times its technique's measured "
                  "fraction), relative distance"});
}

TEST_F(SoftShadowTest, RectangularLightsPenumbraeFollowTheirTwoExtents) {
  const scene::Scene scene = rectangle_edge_scene();
  const double wide = 3.0 * std::tan(glm::radians(10.0)), narrow = 3.0 * std::tan(glm::radians(4.0));
  const int size = 240;
  // The ray tracer's rectangle (the scene light's extents and frame axes).
  reference::Settings rs;
  rs.effect = reference::Effect::soft;
  rs.light_shape = reference::LightShape::rectangle;
  rs.width = rs.height = size;
  rs.samples = 64;
  const reference::Result truth = reference::render(scene, rs);
  EXPECT_EQ(truth.background_pixels, 0u);
  const RampWidths t = rectangle_ramps(scene, truth.visibility);
  fmt::print("rectangle 20° x 8°: ray traced ramps {:.4f} m (expected {:.4f}), {:.4f} m ({:.4f})\n", t.across_width,
             wide, t.across_height, narrow);
  EXPECT_NEAR(t.across_width, wide, 0.03 * wide);
  record_ramp("width", "ray_tracer", t.across_width, wide, 0.03);
  EXPECT_NEAR(t.across_height, narrow, 0.03 * narrow);
  record_ramp("height", "ray_tracer", t.across_height, narrow, 0.03);
  // The environment effect's rectangles (--extracted-lights: how the probe's lights are ray traced):
  // "visibility" is the irradiance over the unoccluded one, so a direction (a, b) of the light
  // weighs (n·d) dω / dA = (1 + a² + b²)^−2 on a surface facing it: the ramp is that weight's
  // distribution along the axis across the edge (cosine_weighted_ramp: 0.5209 m and 0.2093 m).
  {
    rs.effect = reference::Effect::environment;
    rs.probe_lights = true;
    rs.samples = 256;
    const reference::Result lit = reference::render(rectangle_edge_scene(true), rs);
    const RampWidths e = rectangle_ramps(scene, lit.visibility);
    const double wide_cos = cosine_weighted_ramp(1.5, std::tan(glm::radians(10.0)), std::tan(glm::radians(4.0)));
    const double narrow_cos = cosine_weighted_ramp(1.5, std::tan(glm::radians(4.0)), std::tan(glm::radians(10.0)));
    fmt::print("rectangle 20° x 8°: environment (probe lights) ramps {:.4f} m (expected {:.4f}), {:.4f} m ({:.4f})\n",
               e.across_width, wide_cos, e.across_height, narrow_cos);
    EXPECT_NEAR(e.across_width, wide_cos, 0.03 * wide_cos);
    record_ramp("width", "ray_tracer_probe_lights", e.across_width, wide_cos, 0.03);
    EXPECT_NEAR(e.across_height, narrow_cos, 0.03 * narrow_cos);
    record_ramp("height", "ray_tracer_probe_lights", e.across_height, narrow_cos, 0.03);
  }
  Renderer renderer(ctx(), scene);
  for (const std::string t : {"mssm4", "mssm6", "vssm", "pcss", "cssm8", "cssm16"}) {
    RenderSettings s;
    s.technique = t;
    s.width = s.height = size;
    s.shadow_size = 512;
    s.soft_kernel = 27; // PCSS too: the 0.529 m ramp is 22.6 texels of the 12 m map
    const RampWidths r = rectangle_ramps(scene, renderer.render(s).shadow.channel("visibility"));
    fmt::print(
        "rectangle 20° x 8°: {:<7} ramps {:.4f} m ({:+.1f}%), {:.4f} m ({:+.1f}%), ratio {:.3f} (expected {:.3f})\n", t,
        r.across_width, 100.0 * (r.across_width / wide - 1.0), r.across_height,
        100.0 * (r.across_height / narrow - 1.0), r.across_width / r.across_height, wide / narrow);
    const double fraction = kRectangleRampFraction.at(t);
    EXPECT_NEAR(r.across_width, fraction * wide, 0.05 * fraction * wide) << t;
    record_ramp("width", t, r.across_width, fraction * wide, 0.05);
    EXPECT_NEAR(r.across_height, fraction * narrow, 0.05 * fraction * narrow) << t;
    record_ramp("height", t, r.across_height, fraction * narrow, 0.05);
    EXPECT_NEAR(r.across_width / r.across_height, wide / narrow, 0.03 * wide / narrow) << t;
    record_ramp("ratio", t, r.across_width / r.across_height, wide / narrow, 0.03);
  }
}

// RenderSettings::light_height_deg (msm render --light-height-deg, the viewer's height slider): with
// light_extent_deg 20 and height 8 the scene's own 20° x 8° rectangle renders bit-identically; with
// the extent alone the light is a disc (both ramps the wide one); 8 by 20 swaps the two ramps. mssm4,
// the setting of RectangularLightsPenumbraeFollowTheirTwoExtents, its ramp fraction within 5%.
TEST_F(SoftShadowTest, LightHeightSettingMakesEveryLightARectangle) {
  const scene::Scene scene = rectangle_edge_scene();
  const double wide = 3.0 * std::tan(glm::radians(10.0)), narrow = 3.0 * std::tan(glm::radians(4.0));
  const double fraction = kRectangleRampFraction.at("mssm4");
  Renderer renderer(ctx(), scene);
  const auto render = [&](std::optional<float> extent, std::optional<float> height) {
    RenderSettings s;
    s.technique = "mssm4";
    s.width = s.height = 240;
    s.shadow_size = 512;
    s.soft_kernel = 27;
    s.light_extent_deg = extent;
    s.light_height_deg = height;
    return renderer.render(s).shadow.channel("visibility");
  };
  const image::Image own = render({}, {}), same = render(20.0f, 8.0f);
  int different = 0;
  for (int y = 0; y < own.height(); ++y)
    for (int x = 0; x < own.width(); ++x) different += own.at(x, y, 0) != same.at(x, y, 0);
  EXPECT_EQ(different, 0);
  const RampWidths disc = rectangle_ramps(scene, render(20.0f, {}));
  const RampWidths swapped = rectangle_ramps(scene, render(8.0f, 20.0f));
  fmt::print("--light-extent-deg 20: ramps {:.4f} m, {:.4f} m; --light-extent-deg 8 --light-height-deg 20: {:.4f} m, "
             "{:.4f} m\n",
             disc.across_width, disc.across_height, swapped.across_width, swapped.across_height);
  EXPECT_NEAR(disc.across_width, fraction * wide, 0.05 * fraction * wide);
  EXPECT_NEAR(disc.across_height, fraction * wide, 0.05 * fraction * wide);
  EXPECT_NEAR(swapped.across_width, fraction * narrow, 0.05 * fraction * narrow);
  EXPECT_NEAR(swapped.across_height, fraction * wide, 0.05 * fraction * wide);
}

// CSSM on receivers at the far plane of the fitted map (baselines.h, MSM_CSM_BASIS_RANGE): the ground
// of rectangle_edge_scene lies at depth 1 under the plate at depth 0, a blocker a whole depth range
// away. On CSM's unscaled basis the series gave S = 1/2 there (the square wave's jump back at a
// depth difference of 1): visibility 1 in the umbra, no shadow at all, with the rectangle and a
// disc alike. Asserted: under the plate, away from its penumbrae, the mean visibility of cssm8 and
// cssm16 below 0.15 (1 - the scaled series at a difference of 3/4: 0.10 and 0.03 by the damped
// series), as pcss's (0) is; the lit side above 0.95 for all.
TEST_F(SoftShadowTest, CssmShadowsReceiversOnTheFarPlane) {
  const scene::Scene scene = rectangle_edge_scene();
  const glm::mat4 vp = scene.light_view_projection();
  const auto depth = [&](glm::vec3 p) {
    const glm::vec4 c = vp * glm::vec4(p, 1.0f);
    return c.z / c.w;
  };
  ASSERT_GT(depth({0.0f, 0.0f, 0.0f}), 0.999f) << "the ground must lie on the far plane";
  ASSERT_LT(depth({-1.5f, 1.5f, -1.5f}), 0.001f) << "the plate must lie on the near plane";
  const auto mean_over = [&](const image::Image& v, float lo, float hi) {
    double sum = 0.0;
    int n = 0;
    for (float x = lo; x <= hi + 1e-4f; x += 0.1f)
      for (float z = lo; z <= hi + 1e-4f; z += 0.1f, ++n) sum += sample_at(scene, v, {x, 0.0f, z});
    return sum / n;
  };
  Renderer renderer(ctx(), scene);
  for (const bool disc : {false, true})
    for (const std::string t : {"cssm8", "cssm16", "pcss"}) {
      RenderSettings s;
      s.technique = t;
      s.width = s.height = 96;
      s.shadow_size = 256;
      if (disc) s.light_extent_deg = 10.0f;
      const image::Image v = renderer.render(s).shadow.channel("visibility");
      const double umbra = mean_over(v, -1.0f, -0.6f), lit = mean_over(v, 0.6f, 1.0f);
      fmt::print("receivers on the far plane, {}: {:<6} visibility in the umbra {:.4f}, lit {:.4f}\n",
                 disc ? "disc 10°" : "rectangle 20° x 8°", t, umbra, lit);
      EXPECT_LT(umbra, 0.15) << t << (disc ? ", disc" : ", rectangle");
      EXPECT_GT(lit, 0.95) << t << (disc ? ", disc" : ", rectangle");
    }
}

// ---- Kernel widths × light elevations ----
// The disc scene (a disc 0.25 m in radius, 1 m above the ground, seen from 0.6 m straight above its
// shadow) under its 10° disc light at `elevation_deg` towards +x, on a 5 m ground: straight down,
// the disc and the ground are each a plane of one depth in the map, the tables' hardest case; at 30°
// the shadow lies 1.73 m aside, stretched. Penumbrae 0.175 m across at 90° (9 texels of a 256² map
// fitted to the scene), 0.35 m along x at 30°.
scene::Scene disc_scene_at(float elevation_deg) {
  const float e = glm::radians(elevation_deg);
  const float shadow_x = -1.0f / std::tan(e);
  return scene::load_scene_json(fmt::format(R"({{ "msm_scene": 1, "name": "disc_elevation",
      "camera": {{ "position": [{}, 0.6, 0], "target": [{}, 0, 0], "up": [0, 0, -1], "fov_y_deg": 60,
                  "near": 0.01, "far": 10 }},
      "light": {{ "towards_light": [{}, {}, 0], "irradiance": [3, 3, 3], "angular_extent_deg": 10 }},
      "shadow_map": {{ "framing": "fit_scene" }},
      "objects": [
        {{ "name": "ground", "primitive": {{ "type": "plane", "size": [5, 5] }},
           "transform": {{ "translate": [-1.2, 0, 0] }}, "material": {{ "albedo": [0.7, 0.7, 0.7] }} }},
        {{ "name": "disc", "primitive": {{ "type": "cylinder", "radius": 0.25, "height": 0.0001, "segments": 256 }},
           "transform": {{ "translate": [0, 1, 0] }}, "material": {{ "albedo": [0.8, 0.8, 0.8] }} }} ] }})",
                                            shadow_x, shadow_x, std::cos(e), std::sin(e)),
                                ".", "disc_elevation");
}

// For every soft technique and kernel width W of 3, 27, 63, 127 and 255 under the light at 90°, 60°
// and 30°, 160 × 90: either the settings refuse W (a RenderError naming the range: PCSS's loop,
// the moment tables' precision, soft.h) or the visibility is within the bound of the ray tracer's
// (64 samples) that the same technique reaches at the default W = 27, max(1.5 x, x + 0.002) of that
// error; W = 3 clamps the penumbrae and must stay within 10% (or 0.002) of the technique's hard
// shadow, and W = 27 within half of it (soft shadows closer to the area light than hard ones).
// Measured (lavapipe): W = 27 MAE 0.010-0.012 at 90°, 0.014-0.017 at 60°, 0.030-0.051 at 30°; W =
// 63 and 127 within 0.0003 of it at 90° and 60°, 0.0025 at 30° but for vssm (0.049 against 0.038);
// W = 3 0.048 / 0.065 / 0.183, hard 0.054 / 0.071 / 0.189. With the moment bias of 27² kernels at every W and no limit,
// straight down, mssm4 at W = 127 read MAE 0.069 and mssm6 at W = 255 0.030 (bounds 0.015).
TEST_F(SoftShadowTest, EveryKernelWidthIsWithinItsBoundOrRefused) {
  const int width = 160, height = 90;
  for (float elevation : {90.0f, 60.0f, 30.0f}) {
    scene::Scene scene = disc_scene_at(elevation);
    const float extent = scene.light().angular_extent_deg;
    reference::Result truth = area_light_truth(scene, width, height, extent);
    image::Image mask = truth.visibility.channel("background");
    Renderer renderer(ctx(), scene);
    for (const std::string& t : kSoftTechniques) {
      std::map<int, double> mae;
      for (int kernel : {27, 3, 63, 127, 255}) {
        RenderSettings s = soft_settings(t, width, height, extent, 256);
        s.soft_kernel = kernel;
        try {
          s.validate();
        } catch (const RenderError& refused) {
          fmt::print("disc at {}°: {:<6} W = {:3}: refused: {}\n", elevation, t, kernel, refused.what());
          EXPECT_NE(std::string(refused.what()).find("outside [3, "), std::string::npos) << refused.what();
          EXPECT_GE(kernel, 63) << t;
          continue;
        }
        image::Image v = renderer.render(s).shadow.channel("visibility");
        image::Metrics m = image::compute_metrics(v, truth.visibility.channel("visibility"), {.mask = &mask});
        EXPECT_EQ(m.non_finite, 0u) << t << ", W = " << kernel;
        mae[kernel] = m.mae;
        fmt::print("disc at {}°: {:<6} W = {:3}: MAE {:.4f}, leaking {:.4f}, over-darkening {:.4f}\n", elevation, t,
                   kernel, m.mae, m.light_leaking, m.over_darkening);
      }
      // W = 3 clamps every penumbra of the scene (half-widths of 4.5 texels and more, to 1): about
      // the technique's hard shadow (a point light), within 10% or 0.002 of its error.
      RenderSettings hard = soft_settings(t, width, height, 0.0f, 256);
      image::Image hard_v = renderer.render(hard).shadow.channel("visibility");
      const double hard_mae =
          image::compute_metrics(hard_v, truth.visibility.channel("visibility"), {.mask = &mask}).mae;
      fmt::print("disc at {}°: {:<6} hard shadow: MAE {:.4f}\n", elevation, t, hard_mae);
      auto bound = [](double measured) { return std::max(1.5 * measured, measured + 0.002); };
      EXPECT_LT(mae.at(27), 0.5 * hard_mae) << t << " at " << elevation << "°";
      for (auto [kernel, error] : mae)
        EXPECT_LE(error, kernel == 3 ? std::max(1.1 * hard_mae, hard_mae + 0.002) : bound(mae.at(27)))
            << t << " at " << elevation << "°, W = " << kernel << " (W = 27: " << mae.at(27) << ", hard " << hard_mae
            << ")";
    }
  }
}

} // namespace
} // namespace msm::render

namespace msm::render {
namespace {

// Kneiphof §4.2.3 (RenderSettings::front_back_depth): the map stores the mean of the nearest front-
// and back-face depth (a second depth pass culling the faces towards the light). Against the
// ray-traced area light (240x135, 512²), per scene and light: plain, averaged, and averaged without
// the constant depth bias (--depth-bias 0: the paper drops the bias; the receiver plane's slope term
// of soft.h stays). Measured on lavapipe; each bound as expect_near_measured (1.5x
// the measured MAE, at least +0.002). Asserted besides: the averaged map changes the image (the
// back-face pass is in effect: had it culled the wrong side, it would draw the front faces again and
// every pixel would be equal), and a technique that reads no moment map refuses the setting.
struct FrontBackMeasured {
  double plain, averaged, unbiased;
};
const std::map<std::string, std::map<std::string, FrontBackMeasured>> kFrontBackMae = {
    {"column 3",
     {{"mssm4", {0.0019, 0.0017, 0.0017}}, {"mssm6", {0.0011, 0.0017, 0.0017}}, {"cssm16", {0.0087, 0.0144, 0.0144}}}},
    {"column 10",
     {{"mssm4", {0.0080, 0.0077, 0.0076}}, {"mssm6", {0.0075, 0.0073, 0.0073}}, {"cssm16", {0.0170, 0.0252, 0.0252}}}},
    {"models 5",
     {{"mssm4", {0.0053, 0.0054, 0.0054}}, {"mssm6", {0.0044, 0.0050, 0.0050}}, {"cssm16", {0.0132, 0.0261, 0.0260}}}},
};

TEST_F(SoftShadowTest, FrontAndBackFaceAveragedDepth) {
  struct Case {
    const char* scene;
    float extent;
  };
  for (const Case& c : {Case{"column", 3.0f}, Case{"column", 10.0f}, Case{"models", 5.0f}}) {
    scene::Scene scene = scene::builtin_scene(c.scene);
    scene.shadow.mode = scene::ShadowFraming::Mode::fit_scene;
    const reference::Result truth = area_light_truth(scene, 240, 135, c.extent);
    const image::Image mask = truth.visibility.channel("background"), exact = truth.visibility.channel("visibility");
    const std::string key = fmt::format("{} {}", c.scene, int(c.extent));
    Renderer renderer(ctx(), scene);
    for (const std::string t : {"mssm4", "mssm6", "cssm16"}) {
      RenderSettings s = soft_settings(t, 240, 135, c.extent);
      const image::Image plain = renderer.render(s).shadow.channel("visibility");
      s.front_back_depth = true;
      const image::Image averaged = renderer.render(s).shadow.channel("visibility");
      s.depth_bias = 0.0f;
      const image::Image unbiased = renderer.render(s).shadow.channel("visibility");
      const image::Metrics a = image::compute_metrics(plain, exact, {.mask = &mask});
      const image::Metrics b = image::compute_metrics(averaged, exact, {.mask = &mask});
      const image::Metrics u = image::compute_metrics(unbiased, exact, {.mask = &mask});
      fmt::print("{}°: {:<7} MAE {:.4f} -> {:.4f} (front+back) -> {:.4f} (bias 0); leaking {:.4f} -> {:.4f} -> "
                 "{:.4f}; over-darkening {:.4f} -> {:.4f} -> {:.4f}\n",
                 key, t, a.mae, b.mae, u.mae, a.light_leaking, b.light_leaking, u.light_leaking, a.over_darkening,
                 b.over_darkening, u.over_darkening);
      EXPECT_GT(image::compute_metrics(averaged, plain, {.mask = &mask}).mae, 0.0) << key << ", " << t;
      EXPECT_EQ(b.non_finite + u.non_finite, 0u) << key << ", " << t;
      const FrontBackMeasured m = kFrontBackMae.at(key).at(t);
      const auto bound = [](double measured) { return std::max(1.5 * measured, measured + 0.002); };
      EXPECT_LE(a.mae, bound(m.plain)) << key << ", " << t << " (measured " << m.plain << ")";
      EXPECT_LE(b.mae, bound(m.averaged)) << key << ", " << t << " (measured " << m.averaged << ")";
      EXPECT_LE(u.mae, bound(m.unbiased)) << key << ", " << t << " (measured " << m.unbiased << ")";
    }
  }
  Renderer renderer(ctx(), scene::builtin_scene("column"));
  for (const char* t : {"pcss", "pcf", "msm-hamburger-64"}) {
    RenderSettings s = soft_settings(t, 64, 36, 3.0f);
    s.front_back_depth = true;
    EXPECT_THROW(renderer.render(s), RenderError) << t;
  }
}

} // namespace
} // namespace msm::render
