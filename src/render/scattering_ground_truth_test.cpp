// Every scattering technique against the ray-traced ground truth (msm::reference, --effect
// scattering) on the four scattering scenes, and the orderings JCGT 2017 §5 reports, each with
// the margin measured on lavapipe. The signal is the visible fraction of each view ray (the
// renderer's `visible_fraction`, the reference's `visibility`): the in-scattered radiance over the
// ray's maximal scattering f E ∫₀ˢ exp(−σt t) dt, so that "off by > 3% of the maximal scattering"
// is a difference above 0.03. Records the table scattering.* of docs/results.md ("Single scattering
// against the ground truth").
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"

#include "msm/image/metrics.h"
#include "msm/test/figures.h"
#include "msm/test/reference_settings.h"
#include "msm/test/render_settings.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace msm::render {
namespace {

class ScatteringGroundTruthTest : public vk::test::VulkanTest {};

constexpr int kWidth = 160, kHeight = 90, kShadowSize = 512, kReferenceSamples = 256;

const std::vector<std::string> kFilteredTechniques = {"scatter-csm-32", "scatter-msm4-64", "scatter-msm6-96"};

struct Measured {
  double mae, share3; // MAE of the visible fraction, share of pixels off by > 0.03
};
// Measured on lavapipe at 160 x 90, 512² maps, 256 reference samples per pixel (seed 1), with the
// default single Δ(v) per row (one transmittance layer, rectification.h).
// "+filtered": resampling with filtering from the blurred (9 taps), mipmapped moment map (x = 1).
// "+layers": 4 transmittance layers (w = 4; docs/results.md, "Single scattering: transmittance layers").
// "+mips": App. D.5's mips of the prefix sums (RenderSettings::prefix_sum_mips), unfiltered resampling.
// "+adaptive": §5.3.1's adaptive β (z = 2); every other moment row has the proportional β (the default).
const std::map<std::string, std::map<std::string, Measured>> kMeasured = {
    {"tower",
     {{"scatter-march-32", {0.0762, 0.806}},
      {"scatter-march-128", {0.0199, 0.232}},
      {"scatter-csm-32", {0.0561, 0.710}},
      {"scatter-msm4-64", {0.0546, 0.685}},
      {"scatter-msm6-64", {0.0557, 0.697}},
      {"scatter-msm6-96", {0.0548, 0.689}},
      {"scatter-msm6-192", {0.0548, 0.689}},
      {"scatter-csm-32+filtered", {0.0619, 0.744}},
      {"scatter-msm4-64+filtered", {0.0527, 0.704}},
      {"scatter-msm6-96+filtered", {0.0548, 0.722}},
      {"scatter-csm-32+layers", {0.0226, 0.282}},
      {"scatter-msm4-64+layers", {0.0210, 0.242}},
      {"scatter-msm6-96+layers", {0.0210, 0.250}},
      {"scatter-csm-32+mips", {0.0564, 0.712}},
      {"scatter-msm4-64+mips", {0.0547, 0.685}},
      {"scatter-msm6-96+mips", {0.0550, 0.688}},
      {"scatter-msm4-64+adaptive", {0.0625, 0.707}},
      {"scatter-msm6-96+adaptive", {0.0587, 0.692}}}},
    {"trees",
     {{"scatter-march-32", {0.0206, 0.199}},
      {"scatter-march-128", {0.0061, 0.040}},
      {"scatter-csm-32", {0.0168, 0.194}},
      {"scatter-msm4-64", {0.0247, 0.300}},
      {"scatter-msm6-64", {0.0199, 0.255}},
      {"scatter-msm6-96", {0.0188, 0.248}},
      {"scatter-msm6-192", {0.0188, 0.248}},
      {"scatter-csm-32+filtered", {0.0214, 0.270}},
      {"scatter-msm4-64+filtered", {0.0288, 0.358}},
      {"scatter-msm6-96+filtered", {0.0225, 0.299}},
      {"scatter-csm-32+layers", {0.0117, 0.101}},
      {"scatter-msm4-64+layers", {0.0267, 0.326}},
      {"scatter-msm6-96+layers", {0.0157, 0.200}},
      {"scatter-csm-32+mips", {0.0168, 0.194}},
      {"scatter-msm4-64+mips", {0.0248, 0.301}},
      {"scatter-msm6-96+mips", {0.0188, 0.247}},
      {"scatter-msm4-64+adaptive", {0.0629, 0.424}},
      {"scatter-msm6-96+adaptive", {0.0370, 0.357}}}},
    {"gate",
     {{"scatter-march-32", {0.0527, 0.504}},
      {"scatter-march-128", {0.0149, 0.137}},
      {"scatter-csm-32", {0.0715, 0.703}},
      {"scatter-msm4-64", {0.0917, 0.768}},
      {"scatter-msm6-64", {0.0748, 0.736}},
      {"scatter-msm6-96", {0.0740, 0.728}},
      {"scatter-msm6-192", {0.0739, 0.728}},
      {"scatter-csm-32+filtered", {0.0724, 0.673}},
      {"scatter-msm4-64+filtered", {0.0948, 0.835}},
      {"scatter-msm6-96+filtered", {0.0754, 0.790}},
      {"scatter-csm-32+layers", {0.0354, 0.429}},
      {"scatter-msm4-64+layers", {0.0630, 0.545}},
      {"scatter-msm6-96+layers", {0.0412, 0.479}},
      {"scatter-csm-32+mips", {0.0720, 0.704}},
      {"scatter-msm4-64+mips", {0.0918, 0.767}},
      {"scatter-msm6-96+mips", {0.0742, 0.730}},
      {"scatter-msm4-64+adaptive", {0.0998, 0.748}},
      {"scatter-msm6-96+adaptive", {0.0784, 0.732}}}},
    {"room",
     {{"scatter-march-32", {0.0008, 0.006}},
      {"scatter-march-128", {0.0003, 0.000}},
      {"scatter-csm-32", {0.0178, 0.151}},
      {"scatter-msm4-64", {0.0049, 0.055}},
      {"scatter-msm6-64", {0.0045, 0.049}},
      {"scatter-msm6-96", {0.0034, 0.045}},
      {"scatter-msm6-192", {0.0034, 0.045}},
      {"scatter-csm-32+filtered", {0.0207, 0.227}},
      {"scatter-msm4-64+filtered", {0.0049, 0.055}},
      {"scatter-msm6-96+filtered", {0.0035, 0.045}},
      {"scatter-csm-32+layers", {0.0162, 0.128}},
      {"scatter-msm4-64+layers", {0.0047, 0.054}},
      {"scatter-msm6-96+layers", {0.0031, 0.043}},
      {"scatter-csm-32+mips", {0.0178, 0.150}},
      {"scatter-msm4-64+mips", {0.0049, 0.055}},
      {"scatter-msm6-96+mips", {0.0034, 0.045}},
      {"scatter-msm4-64+adaptive", {0.0120, 0.129}},
      {"scatter-msm6-96+adaptive", {0.0082, 0.038}}}},
};

// Bounds: 1.5x the measured MAE, at least the measured MAE + 0.004 (the reference's Monte Carlo
// noise at 256 stratified samples and float rounding across drivers); the share above 3% within
// 0.05 of the measured one.
double mae_bound(double measured) { return std::max(1.5 * measured, measured + 0.004); }
double share_bound(double measured) { return measured + 0.05; }

RenderSettings settings(std::string technique, ParameterValues parameters = {}, bool prefix_sum_mips = false) {
  RenderSettings s = test::render_settings(std::move(technique), kWidth, kHeight, kShadowSize);
  s.parameters = parameters;
  s.prefix_sum_mips = prefix_sum_mips;
  return s;
}

image::Image visible_fraction(const RenderResult& r) { return r.scattering.channel("visible_fraction"); }

reference::Result ground_truth(const scene::Scene& scene) {
  const reference::Settings r =
      test::reference_settings(reference::Effect::scattering, kWidth, kHeight, kReferenceSamples);
  return reference::render(scene, r);
}

// 1 (ignored) for pixels whose view direction is more than max_deg away from the light's
// direction (towards the light): the neighbourhood of the epipole.
image::Image outside_of_the_epipole(const scene::Scene& scene, double max_deg) {
  glm::dmat4 inverse = glm::inverse(glm::dmat4(scene.camera_view_projection(float(kWidth) / float(kHeight))));
  glm::dvec3 origin(scene.camera.position), light = glm::normalize(glm::dvec3(scene.light().towards_light));
  image::Image mask(kWidth, kHeight, 1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      glm::dvec4 far = inverse * glm::dvec4((x + 0.5) / kWidth * 2.0 - 1.0, (y + 0.5) / kHeight * 2.0 - 1.0, 1.0, 1.0);
      glm::dvec3 direction = glm::normalize(glm::dvec3(far) / far.w - origin);
      double degrees = glm::degrees(std::acos(std::clamp(glm::dot(direction, light), -1.0, 1.0)));
      mask.at(x, y, 0) = degrees > max_deg ? 1.0f : 0.0f;
    }
  return mask;
}

// Renders every technique on one scene, checks each against its measured errors, returns the
// metrics by technique.
std::map<std::string, image::Metrics> check_scene(Renderer& renderer, const std::string& name,
                                                  const image::Image& truth) {
  std::map<std::string, image::Metrics> metrics;
  auto scene_measured = kMeasured.find(name);
  struct Run {
    std::string name;
    ParameterValues params;
    bool mips = false;
  };
  std::vector<Run> runs;
  for (const std::string& technique : test::scattering_techniques()) runs.push_back({technique, {}});
  // Resampling with filtering from the blurred, mipmapped moment map (§5.2): "<technique>+filtered".
  for (const std::string& technique : kFilteredTechniques)
    runs.push_back({technique + "+filtered", {{"resampling", 1.0f}}});
  // K transmittance layers instead of the single Δ(v) per row (rectification.h): "<technique>+layers".
  for (const std::string& technique : kFilteredTechniques) runs.push_back({technique + "+layers", {{"layers", 4.0f}}});
  // App. D.5's mips of the prefix sums, read at the pixel's footprint across the rows: "<technique>+mips".
  for (const std::string& technique : kFilteredTechniques) runs.push_back({technique + "+mips", {}, true});
  // §5.3.1's adaptive β instead of the proportional one: "<technique>+adaptive".
  for (const char* technique : {"scatter-msm4-64", "scatter-msm6-96"})
    runs.push_back({std::string(technique) + "+adaptive", {{"beta", 2.0f}}});
  for (const auto& [technique, params, mips] : runs) {
    SCOPED_TRACE(technique);
    RenderResult r = renderer.render(settings(technique.substr(0, technique.find('+')), params, mips));
    image::Metrics m = image::compute_metrics(visible_fraction(r), truth);
    fmt::print("[scattering truth] {:<6} {:<18} MAE {:.4f}  > 3% {:5.1f}%  leaking {:.4f}  non-finite {}\n", name,
               technique, m.mae, 100 * m.share_above_3pct, m.light_leaking, m.non_finite);
    EXPECT_EQ(m.non_finite, 0u);
    metrics[technique] = m;
    if (scene_measured == kMeasured.end() || !scene_measured->second.contains(technique)) {
      ADD_FAILURE() << "no measured value for " << technique << " on " << name;
      continue;
    }
    const Measured& expected = scene_measured->second.at(technique);
    EXPECT_LT(m.mae, mae_bound(expected.mae));
    test::record_figure(
        fmt::format("scattering.{}.{}.mae", name, technique), m.mae,
        {.below = mae_bound(expected.mae),
         .meaning = fmt::format("{}, {}: MAE of the visible fraction against the traced scattering", name, technique)});
    EXPECT_LT(m.share_above_3pct, share_bound(expected.share3));
  }
  return metrics;
}

// The gate's frame-to-frame change of one resampling over another's, with the bound asserted.
void record_flicker(const std::string& technique, const std::string& ratio, double value, double bound) {
  test::record_figure("scattering.flicker." + technique + "." + ratio + ".ratio", value,
                      {.below = bound,
                       .meaning = "gate, a slow drift: mean frame-to-frame change of the visible fraction, one "
                                  "resampling over another"});
}

struct SceneRun {
  scene::Scene scene;
  reference::Result truth;
  image::Image truth_visibility;
};

SceneRun prepare(const std::string& name) {
  SceneRun run{scene::builtin_scene(name), {}, {}};
  run.truth = ground_truth(run.scene);
  run.truth_visibility = run.truth.visibility.channel("visibility");
  return run;
}

// Fig. 14: the tower hides the light, the epipole is in view. Moments ring less than the
// convolution shadow map; adaptive β leaks less near the epipole than β = ½ and β = 1, and the
// proportional β no more than the adaptive one.
TEST_F(ScatteringGroundTruthTest, Tower) {
  SceneRun run = prepare("tower");
  Renderer renderer(ctx(), run.scene);
  std::map<std::string, image::Metrics> m = check_scene(renderer, "tower", run.truth_visibility);
  fmt::print("[ordering] tower MAE: csm-32 {:.4f}, msm4-64 {:.4f}, msm6-96 {:.4f}\n", m["scatter-csm-32"].mae,
             m["scatter-msm4-64"].mae, m["scatter-msm6-96"].mae);
  // Moments ring less than the convolution shadow map: with the proportional β (the default)
  // measured MAE 0.0546 (four) and 0.0548 (six moments) against 0.0561 (CSM-32), margins 0.0015 and
  // 0.0013, asserted at half; with 4 transmittance layers 0.0210 and 0.0210 against 0.0226. With
  // §5.3.1's adaptive β it does not hold (0.0625 and 0.0587; docs/results.md, "The proportional β").
  EXPECT_LT(m["scatter-msm4-64"].mae, m["scatter-csm-32"].mae - 0.5 * 0.0015);
  EXPECT_LT(m["scatter-msm6-96"].mae, m["scatter-csm-32"].mae - 0.5 * 0.0013);
  // Transmittance layers (rectification.h): 4 layers (parameter w = 4) against the paper's single
  // Δ(v) per row (the default), which weighs most rays of the slices through the epipole for another
  // ray length. Measured MAE 0.0226 / 0.0561 (CSM-32), 0.0210 / 0.0546 (four), 0.0210 / 0.0548
  // (six moments): ratios 0.38-0.40.
  for (const char* technique : {"scatter-csm-32", "scatter-msm4-64", "scatter-msm6-96"}) {
    const double layered = m[std::string(technique) + "+layers"].mae;
    fmt::print("[ordering] tower {} MAE: 4 transmittance layers {:.4f}, single delta {:.4f}\n", technique, layered,
               m[technique].mae);
    EXPECT_LT(layered, 0.6 * m[technique].mae) << technique;
  }
  struct Variant {
    const char* technique;
    const char* beta;
    ParameterValues params;
  };
  const ParameterValues adaptive = {{"beta", 2.0f}}, half = {{"beta", 1.0f}, {"fixed_beta", 0.5f}},
                        one = {{"beta", 1.0f}, {"fixed_beta", 1.0f}};
  const Variant variants[] = {{"scatter-msm4-64", "adaptive", adaptive}, {"scatter-msm4-64", "half", half},
                              {"scatter-msm4-64", "one", one},           {"scatter-msm4-64", "proportional", {}},
                              {"scatter-msm6-96", "adaptive", adaptive}, {"scatter-msm6-96", "half", half},
                              {"scatter-msm6-96", "one", one},           {"scatter-msm6-96", "proportional", {}}};
  std::vector<image::Image> images;
  for (const Variant& v : variants)
    images.push_back(visible_fraction(renderer.render(settings(v.technique, v.params))));
  for (double radius : {5.0, 10.0, 20.0}) {
    image::Image mask = outside_of_the_epipole(run.scene, radius);
    std::vector<double> leaking;
    for (size_t i = 0; i < images.size(); ++i) {
      image::Metrics e = image::compute_metrics(images[i], run.truth_visibility, {.mask = &mask});
      leaking.push_back(e.light_leaking);
      fmt::print("[ordering] tower within {:>2}° of the epipole ({} px): {} β {} leaking {:.4f}, MAE {:.4f}\n", radius,
                 e.pixels, variants[i].technique, variants[i].beta, e.light_leaking, e.mae);
    }
    // Within 10°: adaptive β leaks less than β = ½, which leaks less than β = 1, for four and six
    // moments (measured leaking 0.0870 < 0.1212 < 0.1572 and 0.0893 < 0.1066 < 0.1245: ratios 0.72-0.86;
    // the same order at 5° and 20°). The proportional β leaks as little as the adaptive one there
    // (its ramp to the epipole; measured 0.0885 and 0.0898: +1.7% and +0.6%, asserted within 5%).
    if (radius != 10.0) continue;
    for (size_t t : {0u, 4u}) {
      EXPECT_LT(leaking[t], 0.9 * leaking[t + 1]) << variants[t].technique << ": adaptive vs ½";
      EXPECT_LT(leaking[t + 1], 0.9 * leaking[t + 2]) << variants[t].technique << ": ½ vs 1";
      EXPECT_LT(leaking[t + 3], 1.05 * leaking[t]) << variants[t].technique << ": proportional vs adaptive";
    }
  }
}

// Fig. 16: complex shadows of many leaves: six moments have less error than four.
TEST_F(ScatteringGroundTruthTest, Trees) {
  SceneRun run = prepare("trees");
  Renderer renderer(ctx(), run.scene);
  std::map<std::string, image::Metrics> m = check_scene(renderer, "trees", run.truth_visibility);
  fmt::print("[ordering] trees MAE: msm4-64 {:.4f}, msm6-64 {:.4f}, msm6-96 {:.4f}, msm6-192 {:.4f}\n",
             m["scatter-msm4-64"].mae, m["scatter-msm6-64"].mae, m["scatter-msm6-96"].mae, m["scatter-msm6-192"].mae);
  // Measured with the proportional β 0.0188 against 0.0247 (ratio 0.76); 60 bits 0.0199 (0.80);
  // asserted at half the margin. (With §5.3.1's adaptive β: 0.0370 against 0.0629, 0.59.)
  EXPECT_LT(m["scatter-msm6-96"].mae, 0.88 * m["scatter-msm4-64"].mae);
  EXPECT_LT(m["scatter-msm6-64"].mae, 0.90 * m["scatter-msm4-64"].mae);
}

// Fig. 17: the gate's fine shafts. Filtered resampling flickers less than unfiltered under a small
// camera motion: the mean absolute change of the visible fraction between consecutive frames; the
// paper's filtered resampling (from the blurred, mipmapped moment map) less than the bilinear
// moments of the unblurred depth map.
TEST_F(ScatteringGroundTruthTest, Gate) {
  SceneRun run = prepare("gate");
  Renderer renderer(ctx(), run.scene);
  check_scene(renderer, "gate", run.truth_visibility);
  const scene::Camera start = run.scene.camera;
  for (const char* technique : {"scatter-msm4-64", "scatter-msm6-96", "scatter-csm-32"}) {
    // By the parameter x: 0 unfiltered, 1 from the blurred, mipmapped moment map (§5.2), 2 the
    // on-the-fly bilinear moments of the unblurred depth map.
    // 3: unfiltered resampling with App. D.5's mips of the prefix sums.
    double change[4] = {0.0, 0.0, 0.0, 0.0};
    for (int filtered : {0, 1, 2, 3}) {
      image::Image previous;
      for (int frame = 0; frame < 8; ++frame) {
        scene::Camera c = start;
        const glm::vec3 step(0.004f * float(frame), 0.002f * float(frame), 0.0f); // a slow sideways drift
        c.position += step;
        c.target += step;
        renderer.set_camera(c);
        image::Image v = visible_fraction(renderer.render(
            filtered == 3 ? settings(technique, {}, true) : settings(technique, {{"resampling", float(filtered)}})));
        if (frame > 0) change[filtered] += image::compute_metrics(v, previous).mae / 7.0;
        previous = v;
      }
    }
    renderer.set_camera(start);
    fmt::print("[ordering] gate {} mean frame-to-frame change: unfiltered {:.5f}, bilinear {:.5f}, blurred map {:.5f}, "
               "unfiltered with mips of the prefix sums {:.5f}\n",
               technique, change[0], change[2], change[1], change[3]);
    // The bilinear moments: measured 0.00303 vs 0.00634 (four moments), 0.00325 vs 0.00670 (six)
    // and 0.00375 vs 0.00706 (CSM-32): ratio 0.48-0.53.
    EXPECT_LT(change[2], 0.6 * change[0]) << technique;
    record_flicker(technique, "bilinear_over_unfiltered", change[2] / change[0], 0.6);
    // The blurred, mipmapped map flickers less still: measured 0.00142 (four moments), 0.00176
    // (six), 0.00294 (CSM-32): 0.22-0.42x unfiltered, 0.47 and 0.54x the bilinear moments for the
    // moment techniques, 0.78x for CSM-32 (whose 16 terms ring at the shafts' edges either way).
    EXPECT_LT(change[1], 0.5 * change[0]) << technique;
    record_flicker(technique, "blurred_map_over_unfiltered", change[1] / change[0], 0.5);
    const bool moments = technique != std::string("scatter-csm-32");
    EXPECT_LT(change[1], (moments ? 0.7 : 0.9) * change[2]) << technique;
    record_flicker(technique, "blurred_map_over_bilinear", change[1] / change[2], moments ? 0.7 : 0.9);
    // App. D.5's mips of the prefix sums flicker a little less than none (measured 0.00612 / 0.00634,
    // 0.00646 / 0.00670, 0.00688 / 0.00706: 0.96-0.97x): at 160 x 90 and 512 rows few pixels span more
    // than a texel both along and across the rows, the footprint that picks the level.
    EXPECT_LT(change[3], change[0]) << technique;
    record_flicker(technique, "prefix_sum_mips_over_unfiltered", change[3] / change[0], 1.0);
  }
}

// Figs. 15, 19: the room's thin walls. 96 bits leak less than 60 (6 x 10 bits); moments ring less
// than the convolution shadow map.
TEST_F(ScatteringGroundTruthTest, Room) {
  SceneRun run = prepare("room");
  Renderer renderer(ctx(), run.scene);
  std::map<std::string, image::Metrics> m = check_scene(renderer, "room", run.truth_visibility);
  fmt::print("[ordering] room leaking: msm6-64 {:.4f}, msm6-96 {:.4f}; MAE csm-32 {:.4f}, msm4-64 {:.4f}, msm6-96 "
             "{:.4f}\n",
             m["scatter-msm6-64"].light_leaking, m["scatter-msm6-96"].light_leaking, m["scatter-csm-32"].mae,
             m["scatter-msm4-64"].mae, m["scatter-msm6-96"].mae);
  // Measured with the proportional β: leaking 0.0002 vs 0.0009 (ratio 0.22); MAE 0.0034 (six, 96
  // bits) and 0.0049 (four) against 0.0178 (CSM): ratios 0.19, 0.28. (With §5.3.1's adaptive β:
  // leaking 0.0056 vs 0.0106, MAE 0.0082 and 0.0120: ratios 0.53, 0.46, 0.67.)
  EXPECT_LT(m["scatter-msm6-96"].light_leaking, 0.7 * m["scatter-msm6-64"].light_leaking);
  EXPECT_LT(m["scatter-msm6-96"].mae, 0.6 * m["scatter-csm-32"].mae);
  EXPECT_LT(m["scatter-msm4-64"].mae, 0.8 * m["scatter-csm-32"].mae);
}

} // namespace
} // namespace msm::render
