// The renderer against the ray-traced ground truth (msm::reference) on the built-in scenes:
// the two agree on geometry (what is visible where) and on where shadow edges are, and every
// technique's error against the ground truth is bounded. Records each MAE as
// ground_truth.filtered.SCENE.TECHNIQUE.mae.
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/scene/scene.h"
#include "msm/techniques.h"
#include "msm/test/reference_settings.h"
#include "msm/test/render_settings.h"

#include "msm/image/metrics.h"
#include "msm/test/faceted_cylinder.h"
#include "msm/test/figures.h"
#include "msm/test/image_compare.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>

namespace msm::render {
namespace {

// The built-in stress scenes of filtered hard shadows (the smoke scene is for translucency).
const std::vector<std::string> kHardShadowScenes = {"fence", "railing", "stair", "column"};

class GroundTruthTest : public vk::test::VulkanTest {};

// MAE of each technique against the filtered ground truth per scene (in the order of
// kHardShadowScenes), measured on lavapipe. The test records each MAE with its bound: docs/results.md,
// "Figures the tests assert" (keys ground_truth.filtered.SCENE.TECHNIQUE.mae).
const std::map<std::string, std::array<double, 4>> kMeasuredMae = {
    {"plain", {0.0279, 0.0920, 0.0295, 0.0057}},
    {"pcf", {0.0014, 0.0052, 0.0013, 0.0005}},
    {"vsm-32", {0.0127, 0.0325, 0.0148, 0.0008}},
    {"vsm-64", {0.0127, 0.0323, 0.0140, 0.0007}},
    {"esm-32", {0.0203, 0.0488, 0.0219, 0.0016}},
    {"evsm2-32", {0.0154, 0.0380, 0.0163, 0.0009}},
    {"evsm2-64", {0.0249, 0.0504, 0.0238, 0.0024}},
    {"evsm4-64", {0.0105, 0.0348, 0.0145, 0.0008}},
    {"evsm4-128", {0.0105, 0.0304, 0.0127, 0.0011}},
    {"msm-hamburger-128-unit", {0.0083, 0.0261, 0.0122, 0.0022}},
    {"msm-hamburger-128", {0.0112, 0.0238, 0.0159, 0.0122}},
    {"msm-hamburger-64-theta4", {0.0086, 0.0336, 0.0140, 0.0012}},
    {"msm-hamburger-64", {0.0087, 0.0351, 0.0144, 0.0011}},
    {"msm-hausdorff-128-unit", {0.0085, 0.0261, 0.0123, 0.0022}},
    {"msm-hausdorff-128", {0.0113, 0.0238, 0.0160, 0.0122}},
    {"msm-hausdorff-64-theta4", {0.0086, 0.0300, 0.0127, 0.0012}},
    {"msm-hausdorff-64", {0.0086, 0.0307, 0.0127, 0.0012}},
    {"tmsm-128", {0.0098, 0.0242, 0.0144, 0.0083}},
    {"msm6-192", {0.0093, 0.0261, 0.0136, 0.0070}},
    {"msm6-96", {0.0086, 0.0310, 0.0129, 0.0021}},
    {"msm-nl64", {0.0095, 0.0305, 0.0148, 0.0051}},
    {"msm-nl32", {0.0098, 0.0313, 0.0152, 0.0058}},
};

// The bound: 1.5x the measured MAE, and at least the measured MAE plus 0.002 (two references of
// different seeds differ by MAE 0.0019-0.0021: the Monte Carlo noise of 256 samples per pixel).
double mae_bound(double measured) { return std::max(1.5 * measured, measured + 0.002); }

constexpr int kWidth = 200, kHeight = 112, kShadowSize = 512;

RenderSettings settings(std::string technique) {
  RenderSettings s = test::render_settings(std::move(technique), kWidth, kHeight, kShadowSize);
  s.msaa = 4;
  s.mipmaps = false;
  return s;
}

reference::Result ground_truth(const scene::Scene& scene, reference::Effect effect) {
  reference::Settings r;
  r.effect = effect;
  r.width = kWidth;
  r.height = kHeight;
  r.samples = 256;
  r.shadow_size = kShadowSize;
  return reference::render(scene, r);
}

// The renderer's blur/PCF kernel and the ray tracer's filtered footprint are one definition
// (msm/filter.h): for the default and other kernels, the weights are identical, bit for bit.
TEST(FilterKernel, RendererAndRayTracerUseTheSameWeights) {
  for (auto [taps, sigma] : {std::pair{MSM_FILTER_DEFAULT_TAPS, MSM_FILTER_DEFAULT_SIGMA}, std::pair{1, 2.4f},
                             std::pair{15, 1.0f}, std::pair{MSM_FILTER_MAX_TAPS, 30.0f}}) {
    RenderSettings s;
    s.filter_size = taps;
    s.filter_sigma = sigma;
    std::vector<float> renderer = filter_weights(s);
    const reference::FilterKernel kernel(taps, sigma);
    const std::vector<double>& tracer = kernel.weights();
    ASSERT_EQ(renderer.size(), tracer.size());
    for (size_t k = 0; k < renderer.size(); ++k) EXPECT_EQ(double(renderer[k]), tracer[k]) << taps << " taps, k " << k;
    // Settings the ray tracer accepts are the ones the renderer accepts.
    EXPECT_NO_THROW(s.validate());
  }
  reference::Settings r;
  RenderSettings s;
  EXPECT_EQ(r.filter_size, s.filter_size);
  EXPECT_EQ(float(r.filter_sigma), s.filter_sigma);
}

// Pixels where exactly one of the two sees a surface: silhouettes only (a pixel centre within
// rounding of an edge), so a small share.
TEST_F(GroundTruthTest, RasterizerAndRayTracerSeeTheSameSurfaces) {
  for (const std::string& name : kHardShadowScenes) {
    scene::Scene scene = scene::builtin_scene(name);
    Renderer renderer(ctx(), scene);
    image::Image raster = renderer.render(settings("plain")).shadow.channel("background");
    image::Image traced = ground_truth(scene, reference::Effect::hard).visibility.channel("background");
    image::Metrics m = image::compute_metrics(raster, traced);
    EXPECT_LT(m.share_above_10pct, 0.004)
        << name << ": background differs at " << m.share_above_10pct * 100 << "% of the pixels";
  }
}

// PCF with the renderer's kernel and the ray-traced filtered reference (the same kernel over the
// exact visibility of the receiver plane) put shadow edges in the same place: their difference
// is the shadow map's own error (16-bit depth, 4 samples per texel instead of a continuum, the
// depth of the occluder's surface instead of its exact silhouette) plus Monte Carlo noise (256
// samples: standard error <= 0.03 at a penumbra, 0 outside).
TEST_F(GroundTruthTest, PcfAgreesWithTheRayTracedFilteredShadow) {
  for (std::size_t i = 0; i < kHardShadowScenes.size(); ++i) {
    const std::string& name = kHardShadowScenes[i];
    scene::Scene scene = scene::builtin_scene(name);
    Renderer renderer(ctx(), scene);
    RenderResult pcf = renderer.render(settings("pcf"));
    reference::Result truth = ground_truth(scene, reference::Effect::filtered);
    image::Image mask = truth.visibility.channel("background");
    image::Tolerances tolerances;
    tolerances.max_mae = mae_bound(kMeasuredMae.at("pcf")[i]);
    // Pixels off by more than 10%: at most 0.01% since the ground truth takes the renderer's
    // receiver plane and its rule for surfaces turned away from the light (measured; up to 2.5% on
    // the terminators of the stair and the column before).
    tolerances.max_share_above_10pct = 0.03;
    tolerances.max_share_above_3pct = 0.05;
    image::CompareResult c =
        image::compare(pcf.shadow.channel("visibility"), truth.visibility.channel("visibility"), tolerances,
                       {.metrics = {.mask = &mask}, .failure_dir = "test-failures/ground-truth/pcf-" + name});
    EXPECT_TRUE(c.passed) << name << ": " << c.report;
    fmt::print(
        "{:<8} PCF vs ray traced: MAE {:.4f}, leaking {:.4f}, over-darkening {:.4f}, >3% {:.2f}%, >10% {:.2f}%\n", name,
        c.metrics.mae, c.metrics.light_leaking, c.metrics.over_darkening, 100 * c.metrics.share_above_3pct,
        100 * c.metrics.share_above_10pct);
  }
}

// Every technique against the ground truth: MAE and light leaking per scene (printed; the MAE
// recorded as ground_truth.filtered.*), each MAE within mae_bound of its measured value.
TEST_F(GroundTruthTest, EveryTechniqueAgainstTheGroundTruth) {
  std::map<std::string, std::map<std::string, image::Metrics>> table;
  for (std::size_t i = 0; i < kHardShadowScenes.size(); ++i) {
    const std::string& name = kHardShadowScenes[i];
    scene::Scene scene = scene::builtin_scene(name);
    Renderer renderer(ctx(), scene);
    reference::Result truth = ground_truth(scene, reference::Effect::filtered);
    image::Image mask = truth.visibility.channel("background");
    image::Image reference = truth.visibility.channel("visibility");
    for (const Technique* tp : rendered_techniques()) {
      const Technique& t = *tp;
      if (msm_technique_is_area_light(t.id)) continue; // against the area light: soft_shadow_test.cpp
      if (msm_technique_is_scattering(t.id)) continue; // PCF's surfaces; scattering_test.cpp
      image::Metrics m = image::compute_metrics(
          renderer.render(settings(std::string(t.name))).shadow.channel("visibility"), reference, {.mask = &mask});
      ASSERT_TRUE(kMeasuredMae.count(std::string(t.name))) << t.name << " has no measured error";
      EXPECT_LE(m.mae, mae_bound(kMeasuredMae.at(std::string(t.name))[i])) << name << ", " << t.name;
      msm::test::record_figure(
          fmt::format("ground_truth.filtered.{}.{}.mae", name, t.name), m.mae,
          {.below = mae_bound(kMeasuredMae.at(std::string(t.name))[i]),
           .meaning = fmt::format("{}, {}: MAE of visibility against the filtered truth", name, t.name)});
      EXPECT_EQ(m.non_finite, 0u);
      table[std::string(t.name)][name] = m;
    }
  }
  std::string out = "| technique |";
  for (const std::string& name : kHardShadowScenes) out += fmt::format(" {} MAE / leak |", name);
  out += "\n|---|";
  for (size_t i = 0; i < kHardShadowScenes.size(); ++i) out += "---:|";
  out += "\n";
  for (const Technique* tp : rendered_techniques()) {
    const Technique& t = *tp;
    if (msm_technique_is_area_light(t.id) || msm_technique_is_scattering(t.id)) continue;
    out += fmt::format("| {} |", t.name);
    for (const std::string& name : kHardShadowScenes) {
      const image::Metrics& m = table[std::string(t.name)][name];
      out += fmt::format(" {:.4f} / {:.4f} |", m.mae, m.light_leaking);
    }
    out += "\n";
  }
  fmt::print("{}", out);
}

// A cylinder of 16 flat facets under a directional light, lit at every incidence across its side
// (the local lights' counterpart: local_lights_test.cpp). Its vertex normals are the round
// cylinder's: across a facet the interpolated normal turns by up to 11.25 degrees, and a receiver
// plane built from it tilts the more, the more grazing the light, putting the texels beside a lit
// receiver in front of it. The plane is the triangle's, for one map and for cascades alike.
// Over-darkening of the cylinder's side against the traced hard shadow (measured): with the
// interpolated normal's plane PCF 0.1508, plain 0.2606, PCF with two cascades 0.1163; with the
// triangle's 0.0093, 0.0010 and 0.0199 (the rest: where PCF's kernel reaches the ground in front of
// the cylinder's foot, wider with the cascades). Light leaking (measured 0.0107-0.0115, the same
// with either plane): the facet at the terminator, which the tracer shadows where the triangle
// faces away from the light and the renderer's interpolated normal still turns towards it.
TEST_F(GroundTruthTest, DepthTechniquesDoNotShadowTheLitFacetsOfACylinderUnderADirectionalLight) {
  const scene::Scene scene = test::faceted_cylinder_scene(
      R"({"type": "directional", "towards_light": [1.6, 1.0, 0.8], "irradiance": [3, 3, 3]})");
  constexpr int width = 160, height = 120;
  const reference::Result truth =
      reference::render(scene, test::reference_settings(reference::Effect::hard, width, height, 1));
  const image::Image not_cylinder = test::all_but_object(truth.surface.channel("object"), test::kFacetedCylinderObject);
  Renderer renderer(ctx(), scene);
  struct Case {
    const char* technique;
    int cascades;
    double over_darkening, light_leaking; // measured
  };
  const Case cases[] = {{"pcf", 1, 0.0093, 0.0107}, {"plain", 1, 0.0010, 0.0113}, {"pcf", 2, 0.0199, 0.0115}};
  for (const auto& [technique, cascades, over_darkening, light_leaking] : cases) {
    RenderSettings s = test::render_settings(technique, width, height, 256);
    s.msaa = 4;
    s.cascades = cascades;
    const std::string name = fmt::format("{}{}", technique, cascades > 1 ? "-cascades" : "");
    const RenderResult result = renderer.render(s);
    image::Tolerances tolerances;
    tolerances.max_over_darkening = std::max(1.25 * over_darkening, over_darkening + 0.002);
    tolerances.max_light_leaking = std::max(1.25 * light_leaking, light_leaking + 0.002);
    tolerances.max_mae = image::Tolerances::none;
    tolerances.max_share_above_3pct = image::Tolerances::none;
    image::CompareResult c = image::compare(
        result.shadow.channel("visibility"), truth.visibility.channel("visibility"), tolerances,
        {.metrics = {.mask = &not_cylinder}, .failure_dir = "test-failures/ground-truth/facets-" + name});
    EXPECT_TRUE(c.passed) << name << ": " << c.report;
    EXPECT_GT(c.metrics.pixels, 1500u) << name;
    msm::test::record_figure("light.directional.facets." + name + ".over_darkening", c.metrics.over_darkening,
                             {.below = tolerances.max_over_darkening,
                              .meaning = "directional light over a 16-facet cylinder, " + name +
                                         ": over-darkening of its side against the traced hard shadow"});
    fmt::print("cylinder of 16 facets under a directional light, {:<12}: over-darkening {:.4f}, leaking {:.4f}, "
               "MAE {:.4f}\n",
               name, c.metrics.over_darkening, c.metrics.light_leaking, c.metrics.mae);
    // Forward shading takes the triangle's normal from its own derivatives, deferred shading reads
    // the one the surfaces pass stored: the same visibility.
    const double worst = test::forward_deferred_difference(renderer, s);
    EXPECT_LE(worst, 1e-6) << name << ": forward and deferred shading differ";
  }
}

} // namespace
} // namespace msm::render
