// The renderer against the ray-traced ground truth (msm::reference) on the built-in scenes:
// the two agree on geometry (what is visible where) and on where shadow edges are, and every
// technique's error against the ground truth is bounded. Prints the table of docs/results.md.
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/techniques.h"

#include "msm/image/compare.h"
#include "msm/image/metrics.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <map>

namespace msm::render {
namespace {

// The built-in stress scenes of filtered hard shadows (the smoke scene is for translucency).
const std::vector<std::string> kHardShadowScenes = {"fence", "railing", "stair", "column"};

class GroundTruthTest : public vk::test::VulkanTest {};

constexpr int kWidth = 200, kHeight = 112, kShadowSize = 512;

RenderSettings settings(std::string technique) {
  RenderSettings s;
  s.technique = std::move(technique);
  s.width = kWidth;
  s.height = kHeight;
  s.shadow_size = kShadowSize;
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
  for (const std::string& name : kHardShadowScenes) {
    scene::Scene scene = scene::builtin_scene(name);
    Renderer renderer(ctx(), scene);
    RenderResult pcf = renderer.render(settings("pcf"));
    reference::Result truth = ground_truth(scene, reference::Effect::filtered);
    image::Image mask = truth.visibility.channel("background");
    image::Tolerances tolerances;
    tolerances.max_mae = 0.012;
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

// Every technique against the ground truth: MAE and light leaking per scene (the table of
// docs/results.md). The bound is loose (0.07; 0.12 for the unfiltered plain shadow map, measured
// 0.091 on the railing): it catches a technique that is wrong everywhere; the renderer tests
// bound each technique against PCF more tightly.
TEST_F(GroundTruthTest, EveryTechniqueAgainstTheGroundTruth) {
  std::map<std::string, std::map<std::string, image::Metrics>> table;
  for (const std::string& name : kHardShadowScenes) {
    scene::Scene scene = scene::builtin_scene(name);
    Renderer renderer(ctx(), scene);
    reference::Result truth = ground_truth(scene, reference::Effect::filtered);
    image::Image mask = truth.visibility.channel("background");
    image::Image reference = truth.visibility.channel("visibility");
    for (const Technique* tp : rendered_techniques()) {
      const Technique& t = *tp;
      if (msm_technique_is_area_light(t.id)) continue; // against the area light: soft_shadow_test.cpp
      image::Metrics m = image::compute_metrics(
          renderer.render(settings(std::string(t.name))).shadow.channel("visibility"), reference, {.mask = &mask});
      EXPECT_LT(m.mae, t.name == "plain" ? 0.12 : 0.07) << name << ", " << t.name;
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
    if (msm_technique_is_area_light(t.id)) continue;
    out += fmt::format("| {} |", t.name);
    for (const std::string& name : kHardShadowScenes) {
      const image::Metrics& m = table[std::string(t.name)][name];
      out += fmt::format(" {:.4f} / {:.4f} |", m.mae, m.light_leaking);
    }
    out += "\n";
  }
  fmt::print("{}", out);
}

} // namespace
} // namespace msm::render
