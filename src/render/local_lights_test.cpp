// Spot and point lights in the renderer: spot lights' shadows (perspective maps of radial depth)
// and point lights' (six cube faces of it) against the ray tracer's hard and soft shadows per
// technique, the point lights' error along the cube's seams against elsewhere, the maps' per-sample depths against
// the radial distance at the standard sample positions, the spot's unshadowed irradiance
// against a value worked out by hand; the light kinds and techniques it does not draw with them are
// refused with a message that names them, never rendered as if they were absent.
#include "msm/cube_face.h"
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/render/renderer_internals.h"
#include "msm/scene/scene.h"
#include "msm/shading.h"
#include "msm/techniques.h"
#include "msm/test/reference_settings.h"
#include "msm/test/render_settings.h"

#include "msm/image/metrics.h"
#include "msm/test/faceted_cylinder.h"
#include "msm/test/figures.h"
#include "msm/test/image_compare.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace msm::render {
namespace {

class LocalLightsRenderTest : public vk::test::VulkanTest {};

scene::Scene scene_with_lights(const std::string& lights) {
  return scene::load_scene_json(R"({"msm_scene": 1, "lights": [)" + lights + R"(],
    "objects": [{"primitive": {"type": "plane", "size": [4, 4]}},
                {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]}, "transform": {"translate": [0, 0.5, 0]}}]})",
                                std::filesystem::current_path(), "test.json");
}

// A spot 2 m over a 4 m plane, its axis straight down, 0.4 m beside a 0.3 m high box on the plane
// and a small plate 0.3 m below the spot: the plate's shadow (about 1 m across) holds the box and
// the edges of the box's own shadow, where two occluders far apart in depth and a receiver close
// behind the nearer are where VSM leaks light (Chebyshev's bound).
constexpr float kSpotIntensity = 2.0f, kSpotHeight = 2.0f;
const glm::vec3 kSpotFoot(0.4f, 0.0f, 0.2f); // on the plane, straight below the spot

scene::Scene spot_scene() {
  return scene::load_scene_json(fmt::format(R"({{"msm_scene": 1,
    "camera": {{"position": [0, 4, 5], "target": [0, 0, 0], "fov_y_deg": 45}},
    "lights": [{{"type": "spot", "position": [{}, {}, {}], "direction": [0, -1, 0], "inner_cone_deg": 35,
                 "outer_cone_deg": 45, "range": 10, "intensity": [{}, {}, {}]}}],
    "objects": [{{"primitive": {{"type": "plane", "size": [4, 4]}}}},
                {{"primitive": {{"type": "box", "size": [0.5, 0.3, 0.5]}}, "transform": {{"translate": [0, 0.15, 0]}}}},
                {{"primitive": {{"type": "box", "size": [0.16, 0.02, 0.16]}}, "transform": {{"translate": [0.25, 1.7, 0.1]}}}}]}})",
                                            kSpotFoot.x, kSpotHeight, kSpotFoot.z, kSpotIntensity, kSpotIntensity,
                                            kSpotIntensity),
                                std::filesystem::current_path(), "spot.json");
}

constexpr int kWidth = 200, kHeight = 150, kShadowSize = 512;

RenderSettings spot_settings(std::string technique) {
  RenderSettings s = test::render_settings(std::move(technique), kWidth, kHeight, kShadowSize);
  s.msaa = 4;
  return s;
}

// MAE of each hard and filtered technique's visibility against the ray tracer's hard shadow of
// spot_scene (the tracer's exact edges; the renderer's filtered ones are wider: most of the error is
// the penumbra's), measured on lavapipe; the bound is 1.25x that, at least 0.002 more.
const std::map<std::string, double> kSpotMeasuredMae = {{"plain", 0.0003},
                                                        {"pcf", 0.0033},
                                                        {"vsm-32", 0.0066},
                                                        {"msm-hamburger-64", 0.0075},
                                                        {"vsm-64", 0.0068},
                                                        {"esm-32", 0.0062},
                                                        {"evsm2-32", 0.0066},
                                                        {"evsm2-64", 0.0063},
                                                        {"evsm4-64", 0.0066},
                                                        {"evsm4-128", 0.0066},
                                                        {"msm-hamburger-128-unit", 0.0091},
                                                        {"msm-hamburger-128", 0.0095},
                                                        {"msm-hamburger-64-theta4", 0.0078},
                                                        {"msm-hausdorff-128-unit", 0.0096},
                                                        {"msm-hausdorff-128", 0.0095},
                                                        {"msm-hausdorff-64-theta4", 0.0092},
                                                        {"msm-hausdorff-64", 0.0081},
                                                        {"tmsm-128", 0.0091},
                                                        {"msm6-192", 0.0092},
                                                        {"msm6-96", 0.0075},
                                                        {"msm-nl64", 0.0030},
                                                        {"msm-nl32", 0.0031}};

TEST_F(LocalLightsRenderTest, SpotLightShadowsAgreeWithTheRayTracer) {
  const scene::Scene scene = spot_scene();
  const reference::Settings r =
      test::reference_settings(reference::Effect::hard, kWidth, kHeight, reference::Settings{}.samples);
  const reference::Result truth = reference::render(scene, r);
  const image::Image mask = truth.visibility.channel("background");
  Renderer renderer(ctx(), scene);
  for (const Technique* tp : rendered_techniques()) {
    const std::string technique(tp->name);
    if (tp->soft() || msm_technique_is_area_light(tp->id) || tp->scatters()) continue; // refused above
    ASSERT_TRUE(kSpotMeasuredMae.count(technique)) << technique << " has no measured error";
    const double measured = kSpotMeasuredMae.at(technique);
    RenderResult result = renderer.render(spot_settings(technique));
    image::Tolerances tolerances;
    tolerances.max_mae = std::max(1.25 * measured, measured + 0.002);
    // The filtered edges against the tracer's hard ones: up to 7.6% of the pixels (MSM 32 non-linear,
    // its scattered over-darkening; the others up to 4.3%) differ by more than 3%, 3.3% by more
    // than 10% (measured); the MAE, per technique, bounds the error.
    tolerances.max_share_above_3pct = 0.09;
    tolerances.max_share_above_10pct = 0.04;
    image::CompareResult c =
        image::compare(result.shadow.channel("visibility"), truth.visibility.channel("visibility"), tolerances,
                       {.metrics = {.mask = &mask}, .failure_dir = "test-failures/local-lights/spot-" + technique});
    EXPECT_TRUE(c.passed) << technique << ": " << c.report;
    msm::test::record_figure(
        "light.spot." + technique + ".mae", c.metrics.mae,
        {.below = tolerances.max_mae,
         .meaning = "spot light, " + technique + ": MAE of visibility against the traced hard shadow"});
    EXPECT_EQ(c.metrics.non_finite_in_test, 0u) << technique;
    EXPECT_EQ(image::compute_metrics(result.color, truth.radiance).non_finite_in_test, 0u) << technique;
    fmt::print("spot, {:<18} vs ray traced: MAE {:.4f}, leaking {:.4f}, over-darkening {:.4f}\n", technique,
               c.metrics.mae, c.metrics.light_leaking, c.metrics.over_darkening);
  }
}

// The pixel that sees the plane straight below the spot: E = I / h² = 0.5 W/m² at normal incidence
// (no cone falloff on the axis), so its colour is the Lambertian albedo / π E plus the ambient
// (msm/shading.h), tone mapped; the 8-bit target rounds by less than 2%.
TEST_F(LocalLightsRenderTest, SpotLightIrradianceBelowTheSpotIsIntensityOverHeightSquared) {
  const scene::Scene scene = spot_scene();
  const RenderSettings s = spot_settings("pcf");
  const glm::vec4 clip = scene.camera_view_projection(float(kWidth) / float(kHeight)) * glm::vec4(kSpotFoot, 1.0f);
  const glm::vec2 ndc = glm::vec2(clip) / clip.w;
  const int x = int(std::floor((ndc.x * 0.5f + 0.5f) * float(kWidth)));
  const int y = int(std::floor((ndc.y * 0.5f + 0.5f) * float(kHeight)));
  ASSERT_TRUE(x >= 0 && x < kWidth && y >= 0 && y < kHeight) << x << ", " << y;
  const float irradiance = kSpotIntensity / (kSpotHeight * kSpotHeight);
  const glm::vec3 albedo = scene.materials.at(scene.objects.at(0).material).albedo;
  const glm::vec3 expected = msm_aces(albedo * (irradiance / float(M_PI) + MSM_AMBIENT) * s.exposure);
  Renderer renderer(ctx(), scene);
  const RenderResult result = renderer.render(s);
  EXPECT_NEAR(result.shadow.at(x, y, result.shadow.find_channel("visibility")), 1.0f, 1e-3f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(result.color.at(x, y, c), expected[c], 0.02f * expected[c]) << c;
}

scene::Scene spot_beam_scene(bool light_in_view = true); // below: a spot's beam in a medium

// What the renderer does not draw with spot lights is refused by name, never drawn without them:
// the prefiltered scattering with a filtered resampling or transmittance layers, a spot without range.
TEST_F(LocalLightsRenderTest, SpotLightsWithFilteredRectificationOrWithoutRangeAreRefused) {
  {
    Renderer renderer(ctx(), spot_beam_scene());
    struct Refused {
      std::string technique, parameter;
      float value;
    };
    for (const Refused& r : {Refused{"scatter-msm4-64", "resampling", 1.0f}, // filtered
                             Refused{"scatter-csm-32", "resampling", 2.0f},  // bilinear-moments
                             Refused{"scatter-msm4-64", "layers", 4.0f}}) {
      RenderSettings s = spot_settings(r.technique);
      s.parameters[r.parameter] = r.value;
      try {
        renderer.render(s);
        ADD_FAILURE() << "no RenderError for " << r.technique << " " << r.parameter << " with a spot light";
      } catch (const RenderError& e) {
        EXPECT_NE(std::string(e.what()).find("spot"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(r.parameter), std::string::npos) << e.what();
      }
    }
  }
  const scene::Scene unbounded =
      scene_with_lights(R"({"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0]})");
  Renderer renderer(ctx(), unbounded);
  try {
    renderer.render(spot_settings("pcf"));
    ADD_FAILURE() << "no RenderError for a spot light without range";
  } catch (const RenderError& e) { EXPECT_NE(std::string(e.what()).find("range"), std::string::npos) << e.what(); }
}

// ---- Soft shadows of a spot light of some radius ----
// A spot (a sphere of radius 0.1 m) 2 m over the ground, its axis straight down; a thin plate
// 0.4 m wide 0.5 m below it and a 0.8 m high box beside, whose top the plate's shadow edge crosses.
// The lines from the plate's edge (±0.2, 1.5) that touch the sphere leave it at 21.80° ± 10.70°
// from the vertical (atan(0.2 / 0.5) ± asin(0.1 / 0.5385)), so the penumbra spans x in [-1.156,
// -0.494] on the ground (0.662 m) and [0.337, 0.646] on the box's top, 0.7 m lower than the plate
// (0.309 m): 2 R (r_f - r_b) / r_b of the similar triangles, 0.6 m and 0.28 m, widened off the axis.
// Their 10%-90% widths are 0.687 of those (a disc's straight edge, soft_shadow_test's
// PenumbraeWidenWithReceiverDistance): 0.455 m and 0.212 m. The camera looks down from behind the
// plate's shadow, so that the plate hides none of the two lines. The range, 3.5 m, just holds the
// lit ground: the map's depths (distance / range) use the most of [0, 1] (CSSM's series needs it).
scene::Scene soft_spot_scene() {
  return scene::load_scene_json(R"({"msm_scene": 1,
    "camera": {"position": [0, 4.2, 2.0], "target": [0, 0, 0.2], "fov_y_deg": 50},
    "lights": [{"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0], "inner_cone_deg": 40,
                "outer_cone_deg": 50, "range": 3.5, "intensity": [2, 2, 2], "radius": 0.1}],
    "objects": [{"primitive": {"type": "plane", "size": [4, 4]}},
                {"primitive": {"type": "box", "size": [0.4, 0.02, 0.4]}, "transform": {"translate": [0, 1.5, 0]}},
                {"primitive": {"type": "box", "size": [0.7, 0.8, 1.0]}, "transform": {"translate": [0.55, 0.4, 0]}}]})",
                                std::filesystem::current_path(), "soft-spot.json");
}

constexpr int kSoftSize = 160, kSoftShadowSize = 128;

// The 10%-90% width (metres) of the visibility's ramp along the world segment from a (lit) to b
// (in umbra), sampled at the pixels the segment projects to.
double ramp_width(const scene::Scene& scene, const image::Image& visibility, glm::vec3 a, glm::vec3 b) {
  const glm::mat4 view_projection = scene.camera_view_projection(1.0f);
  const int steps = 400;
  std::vector<float> v(steps + 1);
  for (int i = 0; i <= steps; ++i) {
    const glm::vec4 clip = view_projection * glm::vec4(glm::mix(a, b, float(i) / float(steps)), 1.0f);
    const glm::vec2 ndc = glm::vec2(clip) / clip.w;
    const int x =
        std::clamp(int(std::floor((ndc.x * 0.5f + 0.5f) * float(visibility.width()))), 0, visibility.width() - 1);
    const int y =
        std::clamp(int(std::floor((ndc.y * 0.5f + 0.5f) * float(visibility.height()))), 0, visibility.height() - 1);
    v[size_t(i)] = visibility.at(x, y, 0);
  }
  const auto crossing = [&](float level) {
    for (int i = 0; i < steps; ++i)
      if (v[size_t(i)] >= level && v[size_t(i + 1)] < level)
        return (double(i) + double(v[size_t(i)] - level) / double(v[size_t(i)] - v[size_t(i + 1)])) / steps;
    return 1.0;
  };
  return std::abs(crossing(0.1f) - crossing(0.9f)) * double(glm::length(b - a));
}

struct PenumbraWidths {
  double ground, box_top;
};
PenumbraWidths spot_penumbra_widths(const scene::Scene& scene, const image::Image& visibility) {
  return {ramp_width(scene, visibility, {-1.4f, 0.0f, 0.0f}, {-0.25f, 0.0f, 0.0f}),
          ramp_width(scene, visibility, {0.85f, 0.8f, 0.0f}, {0.25f, 0.8f, 0.0f})};
}

RenderSettings soft_spot_settings(std::string technique) {
  RenderSettings s = test::render_settings(std::move(technique), kSoftSize, kSoftSize, kSoftShadowSize);
  s.soft_kernel = 23; // the ground's penumbra is 19 texels wide
  return s;
}

// MAE of each soft technique's visibility against the ray tracer's soft shadow of soft_spot_scene,
// measured on lavapipe; the bound is 1.25x that, at least 0.002 more. CSSM's series leaves the
// plate's umbra on the ground grey (0.04-0.05 leaking, twice PCF's error: the technique's
// reconstruction, not the spot's sizes, which it shares with the others), so its penumbrae are not
// measured; VSSM leaks as with directional lights (Chebyshev's bound), about as far from the truth as
// the hard PCF.
struct SoftSpotExpectation {
  double mae;
  bool beats_hard_shadows; // closer to the ray tracer than PCF's hard shadow, penumbrae checked
};
const std::map<std::string, SoftSpotExpectation> kSoftSpotMeasured = {
    {"pcss", {0.0139, true}},  {"mssm4", {0.0141, true}},  {"mssm6", {0.0157, true}},
    {"vssm", {0.0293, false}}, {"cssm8", {0.0452, false}}, {"cssm16", {0.0508, false}}};

// The soft techniques against the ray traced sphere: the error per technique; for those that beat
// the hard shadow the penumbra widths on both receivers (within 30% and 3 cm of the ray tracer's,
// more than 1.5 times as wide on the ground as on the box: 2.0 ray traced); four moments leak less
// than two (VSSM).
TEST_F(LocalLightsRenderTest, SpotLightSoftShadowsAgreeWithTheRayTracer) {
  const scene::Scene scene = soft_spot_scene();
  const reference::Settings r = test::reference_settings(reference::Effect::soft, kSoftSize, kSoftSize, 64);
  const reference::Result truth = reference::render(scene, r);
  const image::Image mask = truth.visibility.channel("background");
  const image::Image truth_visibility = truth.visibility.channel("visibility");
  const PenumbraWidths expected = spot_penumbra_widths(scene, truth_visibility);
  fmt::print("spot penumbra 10%-90% (m): ray traced ground {:.3f}, box top {:.3f}\n", expected.ground,
             expected.box_top);
  EXPECT_NEAR(expected.ground, 0.687 * 0.662, 0.1 * 0.687 * 0.662);
  EXPECT_NEAR(expected.box_top, 0.687 * 0.309, 0.1 * 0.687 * 0.309);
  Renderer renderer(ctx(), scene);
  const image::Metrics hard = image::compute_metrics(
      renderer.render(soft_spot_settings("pcf")).shadow.channel("visibility"), truth_visibility, {.mask = &mask});
  std::map<std::string, double> leaking;
  for (const auto& [technique, measured] : kSoftSpotMeasured) {
    const RenderResult result = renderer.render(soft_spot_settings(technique));
    const image::Image visibility = result.shadow.channel("visibility");
    image::Tolerances tolerances;
    tolerances.max_mae = std::max(1.25 * measured.mae, measured.mae + 0.002);
    tolerances.max_share_above_3pct = 1.0;
    tolerances.max_share_above_10pct = 1.0;
    const image::CompareResult c = image::compare(
        visibility, truth_visibility, tolerances,
        {.metrics = {.mask = &mask}, .failure_dir = "test-failures/local-lights/soft-spot-" + technique});
    const PenumbraWidths got = spot_penumbra_widths(scene, visibility);
    fmt::print("soft spot, {:<7} vs ray traced: MAE {:.4f} (pcf {:.4f}), leaking {:.4f}, penumbra ground {:.3f}, box "
               "top {:.3f}\n",
               technique, c.metrics.mae, hard.mae, c.metrics.light_leaking, got.ground, got.box_top);
    leaking[technique] = c.metrics.light_leaking;
    EXPECT_TRUE(c.passed) << technique << ": " << c.report;
    msm::test::record_figure(
        "light.spot_soft." + technique + ".mae", c.metrics.mae,
        {.below = tolerances.max_mae,
         .meaning = "spot light of radius 0.1 m, " + technique + ": MAE of visibility against the traced soft shadow"});
    EXPECT_EQ(c.metrics.non_finite_in_test, 0u) << technique;
    EXPECT_EQ(image::compute_metrics(result.color, truth.radiance).non_finite_in_test, 0u) << technique;
    if (!measured.beats_hard_shadows) continue;
    EXPECT_LT(c.metrics.mae, hard.mae) << technique;
    EXPECT_NEAR(got.ground, expected.ground, 0.3 * expected.ground + 0.03) << technique;
    EXPECT_NEAR(got.box_top, expected.box_top, 0.3 * expected.box_top + 0.03) << technique;
    EXPECT_GT(got.ground, 1.5 * got.box_top) << technique;
  }
  EXPECT_LT(leaking["mssm4"], 0.5 * leaking["vssm"]); // measured 0.0076 against 0.0212
}
// ---- Single scattering from a spot light (ray marching) ----
// A spot 2 m over the ground, cones 25°/30°, range 6 m, in a medium of extinction 0.2 (isotropic,
// albedo 1); a plate 0.3 m wide 0.8 m below the light cuts a shadow shaft out of its beam. The
// camera looks at the beam from the side, so that the rays cross the lit cone, the shaft and the
// dark medium outside the cone; a wall behind ends every ray within 8 m (ray marching spaces its
// samples evenly over the ray: over a ray to the far plane they would step over the beam).
// light_in_view false: the camera looks down at the beam from the side, the light above the view.
scene::Scene spot_beam_scene(bool light_in_view) {
  const std::string camera =
      light_in_view ? R"("camera": {"position": [0, 1, 4.5], "target": [0, 0.9, 0], "fov_y_deg": 50},)"
                    : R"("camera": {"position": [2.5, 0.8, 3.0], "target": [0, 0.5, 0], "fov_y_deg": 40},)";
  return scene::load_scene_json(R"({"msm_scene": 1,
    )" + camera + R"(
    "lights": [{"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0], "inner_cone_deg": 25,
                "outer_cone_deg": 30, "range": 6, "intensity": [4, 4, 4]}],
    "medium": {"extinction": 0.2, "scattering_albedo": 1},
    "objects": [{"primitive": {"type": "plane", "size": [6, 6]}},
                {"primitive": {"type": "box", "size": [0.3, 0.02, 0.3]}, "transform": {"translate": [0, 1.2, 0]}},
                {"primitive": {"type": "box", "size": [10, 6, 0.2]}, "transform": {"translate": [0, 3, -3.1]}}]})",
                                std::filesystem::current_path(), "spot-beam.json");
}

// A render's in-scattered luminance against the ray tracer's: the mean absolute difference over
// the mean, and the MAE of the rays' visible fraction.
struct ScatteringError {
  double inscattered, visible_fraction;
  std::size_t non_finite;
};
ScatteringError scattering_error(const RenderResult& result, const reference::Result& truth) {
  const int width = result.scattering.width(), height = result.scattering.height();
  double difference = 0.0, mean = 0.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const glm::vec3 got(result.scattering.at(x, y, 0), result.scattering.at(x, y, 1), result.scattering.at(x, y, 2));
      const glm::vec3 want(truth.scattering.at(x, y, 0), truth.scattering.at(x, y, 1), truth.scattering.at(x, y, 2));
      difference += std::abs(double(msm_luminance(got)) - double(msm_luminance(want)));
      mean += msm_luminance(want);
    }
  const image::Metrics m =
      image::compute_metrics(result.scattering.channel("visible_fraction"), truth.visibility.channel("visibility"));
  return {difference / mean, m.mae, m.non_finite};
}

constexpr int kBeamWidth = 128, kBeamHeight = 96;

const reference::Result& spot_beam_truth(bool light_in_view) {
  static std::map<bool, reference::Result> truths;
  auto it = truths.find(light_in_view);
  if (it == truths.end())
    it = truths
             .emplace(light_in_view, reference::render(spot_beam_scene(light_in_view),
                                                       test::reference_settings(reference::Effect::scattering,
                                                                                kBeamWidth, kBeamHeight, 256)))
             .first;
  return it->second;
}

// Each technique's in-scattered luminance against the ray tracer's (256 samples per ray): the
// mean absolute difference over the mean (measured on lavapipe; bound 1.5x, at least 0.02 more);
// the ray's visible fraction's MAE likewise (bound 1.5x, at least 0.01 more).
std::map<std::string, ScatteringError>
expect_spot_beam_scattering(Renderer& renderer, const std::map<std::string, std::pair<double, double>>& measured,
                            bool light_in_view = true) {
  const reference::Result& truth = spot_beam_truth(light_in_view);
  std::map<std::string, ScatteringError> errors;
  for (const auto& [technique, expected] : measured) {
    const RenderResult result = renderer.render(test::render_settings(technique, kBeamWidth, kBeamHeight, 256));
    const ScatteringError e = scattering_error(result, truth);
    fmt::print("spot scattering{}, {:<17} vs ray traced: in-scattered luminance mean absolute error / mean {:.4f}, "
               "visible fraction MAE {:.4f}, non-finite {}\n",
               light_in_view ? "" : " (light out of view)", technique, e.inscattered, e.visible_fraction, e.non_finite);
    EXPECT_EQ(e.non_finite, 0u) << technique;
    EXPECT_EQ(image::compute_metrics(result.color, truth.radiance).non_finite_in_test, 0u) << technique;
    EXPECT_LT(e.inscattered, std::max(1.5 * expected.first, expected.first + 0.02)) << technique;
    // The visible fraction through the image comparison, which writes the images where it fails.
    image::Tolerances tolerances;
    tolerances.max_mae = std::max(1.5 * expected.second, expected.second + 0.01);
    tolerances.max_share_above_3pct = image::Tolerances::none;
    const image::CompareResult c = image::compare(
        result.scattering.channel("visible_fraction"), truth.visibility.channel("visibility"), tolerances,
        {.failure_dir = "test-failures/local-lights/spot-scattering-" + technique + (light_in_view ? "" : "-side")});
    EXPECT_TRUE(c.passed) << technique << ": " << c.report;
    errors[technique] = e;
  }
  return errors;
}

// 32 samples over rays of 5-8 m step over the plate's 0.3 m shaft unevenly (the per-pixel jitter's
// noise), 128 much less.
TEST_F(LocalLightsRenderTest, SpotLightScatteringByRayMarchingAgreesWithTheRayTracer) {
  Renderer renderer(ctx(), spot_beam_scene());
  expect_spot_beam_scattering(renderer,
                              {{"scatter-march-32", {0.1730, 0.0025}}, {"scatter-march-128", {0.0456, 0.0016}}});
}

// The prefiltered scattering of a spot light (rectification.h's spot section): its map resampled
// along the light's rays at their angle ψ, prefix sums weighed at each slice's mean γ, one lookup
// per pixel times the unshadowed in-scattering integrated over ψ. Measured: closer to the ray
// tracer than ray marching with 32 samples (0.063 against 0.173 for four moments), less close
// than with 128 (0.046); most of the visible fraction's error is the moments' over-darkening of the
// lit cone and of the shaft's top just below the plate (β's share of the ray's own depth).
TEST_F(LocalLightsRenderTest, SpotLightPrefilteredScatteringAgreesWithTheRayTracer) {
  Renderer renderer(ctx(), spot_beam_scene());
  std::map<std::string, ScatteringError> e =
      expect_spot_beam_scattering(renderer, {{"scatter-msm4-64", {0.0630, 0.0050}},
                                             {"scatter-msm6-64", {0.0669, 0.0067}},
                                             {"scatter-csm-32", {0.0565, 0.0118}},
                                             {"scatter-march-32", {0.1730, 0.0025}}});
  for (const char* technique : {"scatter-msm4-64", "scatter-msm6-64", "scatter-csm-32"}) {
    EXPECT_LT(e[technique].inscattered, 0.5 * e["scatter-march-32"].inscattered) << technique;
    msm::test::record_figure(std::string("scattering.spot.") + technique + ".inscattered_error",
                             e[technique].inscattered,
                             {.below = 0.5 * e["scatter-march-32"].inscattered,
                              .meaning = std::string("a spot's beam cut by a plate, prefiltered ") + technique +
                                         ": in-scattered luminance mean absolute error over the mean against the ray "
                                         "tracer (bound: half of ray marching's with 32 samples)"});
  }
  // The light just above the view: the slices a wedge of φ (the epipole out of view), not the full
  // circle. Measured 0.045 against ray marching's 0.156 with 32 samples.
  Renderer side(ctx(), spot_beam_scene(false));
  std::map<std::string, ScatteringError> s = expect_spot_beam_scattering(
      side, {{"scatter-msm4-64", {0.0448, 0.0063}}, {"scatter-march-32", {0.1558, 0.0062}}}, false);
  EXPECT_LT(s["scatter-msm4-64"].inscattered, s["scatter-march-32"].inscattered);
}

// A point light 1 m over a plane among columns 0.8 m high at 0.6 m from the light's foot: their
// shadows run outwards across the seams of the light's cube, one (at 45 degrees) along the seam of
// two side faces, the others across the square where the bottom face meets the side faces (1 m
// out). `turn_deg` turns the whole scene and its camera about the vertical through the light: the
// image is the same, the seams fall elsewhere on it.
constexpr float kPointIntensity = 1.5f, kPointHeight = 1.0f;
const std::vector<float> kColumnAngles = {0.0f, 45.0f, 100.0f, 160.0f, 215.0f, 290.0f};

// `radius` > 0: the light is a sphere of that radius (soft shadows), and `range` ends it.
scene::Scene point_scene(float turn_deg = 0.0f, float radius = 0.0f, float range = 10.0f) {
  const glm::mat4 turn = glm::rotate(glm::mat4(1.0f), glm::radians(turn_deg), glm::vec3(0.0f, 1.0f, 0.0f));
  auto turned = [&](glm::vec3 p) { return glm::vec3(turn * glm::vec4(p, 1.0f)); };
  std::string objects = fmt::format(R"({{"primitive": {{"type": "plane", "size": [8, 8]}},
      "transform": {{"rotate": [0, {}, 0]}}}})",
                                    turn_deg);
  for (float a : kColumnAngles) {
    const glm::vec3 c = turned(glm::vec3(0.6f * std::cos(glm::radians(a)), 0.4f, 0.6f * std::sin(glm::radians(a))));
    objects += fmt::format(R"(, {{"primitive": {{"type": "box", "size": [0.12, 0.8, 0.12]}},
      "transform": {{"translate": [{}, {}, {}], "rotate": [0, {}, 0]}}}})",
                           c.x, c.y, c.z, turn_deg - a);
  }
  // A small plate over the column at 0 degrees: its shadow (1.2 m out, across the bottom face's
  // seam) holds the column's, two occluders far apart in depth, where VSM leaks.
  const glm::vec3 plate = turned(glm::vec3(0.3f, 0.75f, 0.0f));
  objects += fmt::format(R"(, {{"primitive": {{"type": "box", "size": [0.16, 0.02, 0.16]}},
      "transform": {{"translate": [{}, {}, {}], "rotate": [0, {}, 0]}}}})",
                         plate.x, plate.y, plate.z, turn_deg);
  const glm::vec3 eye = turned(glm::vec3(0.3f, 4.0f, 2.8f));
  return scene::load_scene_json(fmt::format(R"({{"msm_scene": 1,
    "camera": {{"position": [{}, {}, {}], "target": [0, 0, 0], "fov_y_deg": 55}},
    "lights": [{{"type": "point", "position": [0, {}, 0], "range": {}, "intensity": [{}, {}, {}]{}}}],
    "objects": [{}]}})",
                                            eye.x, eye.y, eye.z, kPointHeight, range, kPointIntensity, kPointIntensity,
                                            kPointIntensity,
                                            radius > 0.0f ? fmt::format(R"(, "radius": {})", radius) : "", objects),
                                std::filesystem::current_path(), "point.json");
}

constexpr int kPointImageWidth = 200, kPointImageHeight = 150, kPointShadowSize = 256;

RenderSettings point_settings(std::string technique) {
  RenderSettings s = test::render_settings(std::move(technique), kPointImageWidth, kPointImageHeight, kPointShadowSize);
  s.msaa = 4;
  return s;
}

reference::Result point_truth(const scene::Scene& scene) {
  const reference::Settings r = test::reference_settings(reference::Effect::hard, kPointImageWidth, kPointImageHeight,
                                                         reference::Settings{}.samples);
  return reference::render(scene, r);
}

// MAE of each hard and filtered technique's visibility against the ray tracer's hard shadow of
// point_scene, measured on lavapipe; the bound is 1.25x that, at least 0.002 more. Most of it is
// the filtered penumbrae against the tracer's exact edges and, for the 128-bit, six-moment and
// non-linear maps, over-darkening of the ground at grazing light beyond 2 m from the light's foot
// (docs/techniques.md, "Light kinds").
const std::map<std::string, double> kPointMeasuredMae = {{"plain", 0.0044},
                                                         {"pcf", 0.0232},
                                                         {"vsm-32", 0.0266},
                                                         {"vsm-64", 0.0266},
                                                         {"esm-32", 0.0355},
                                                         {"evsm2-32", 0.0271},
                                                         {"evsm2-64", 0.0452},
                                                         {"evsm4-64", 0.0270},
                                                         {"evsm4-128", 0.0270},
                                                         {"msm-hamburger-128-unit", 0.0544},
                                                         {"msm-hamburger-128", 0.0887},
                                                         {"msm-hamburger-64-theta4", 0.0385},
                                                         {"msm-hamburger-64", 0.0380},
                                                         {"msm-hausdorff-128-unit", 0.0545},
                                                         {"msm-hausdorff-128", 0.0888},
                                                         {"msm-hausdorff-64-theta4", 0.0388},
                                                         {"msm-hausdorff-64", 0.0383},
                                                         {"tmsm-128", 0.0876},
                                                         {"msm6-192", 0.0957},
                                                         {"msm6-96", 0.0487},
                                                         {"msm-nl64", 0.0783},
                                                         {"msm-nl32", 0.0734}};

TEST_F(LocalLightsRenderTest, PointLightShadowsAgreeWithTheRayTracer) {
  const scene::Scene scene = point_scene();
  const reference::Result truth = point_truth(scene);
  const image::Image mask = truth.visibility.channel("background");
  Renderer renderer(ctx(), scene);
  std::map<std::string, double> leaking;
  for (const Technique* tp : rendered_techniques()) {
    const std::string technique(tp->name);
    // The soft techniques: PointLightSoftShadowsAgreeWithTheRayTracer; scattering is refused.
    if (tp->soft() || msm_technique_is_area_light(tp->id) || tp->scatters()) continue;
    ASSERT_TRUE(kPointMeasuredMae.count(technique)) << technique << " has no measured error";
    const double measured = kPointMeasuredMae.at(technique);
    RenderResult result = renderer.render(point_settings(technique));
    image::Tolerances tolerances;
    tolerances.max_mae = std::max(1.25 * measured, measured + 0.002);
    // The shares of pixels off by more than 3% and 10% (4% to 65% and 4% to 44%, measured) follow
    // the MAE; the MAE, per technique, bounds the error.
    tolerances.max_share_above_3pct = 1.0;
    tolerances.max_share_above_10pct = 1.0;
    image::CompareResult c =
        image::compare(result.shadow.channel("visibility"), truth.visibility.channel("visibility"), tolerances,
                       {.metrics = {.mask = &mask}, .failure_dir = "test-failures/local-lights/point-" + technique});
    EXPECT_TRUE(c.passed) << technique << ": " << c.report;
    msm::test::record_figure(
        "light.point." + technique + ".mae", c.metrics.mae,
        {.below = tolerances.max_mae,
         .meaning = "point light among columns, " + technique + ": MAE of visibility against the traced hard shadow"});
    EXPECT_EQ(c.metrics.non_finite_in_test, 0u) << technique;
    EXPECT_EQ(image::compute_metrics(result.color, truth.radiance).non_finite_in_test, 0u) << technique;
    leaking[technique] = c.metrics.light_leaking;
    fmt::print(
        "point, {:<18} vs ray traced: MAE {:.4f}, leaking {:.4f}, over-darkening {:.4f}, >3% {:.3f}, >10% {:.3f}\n",
        technique, c.metrics.mae, c.metrics.light_leaking, c.metrics.over_darkening, c.metrics.share_above_3pct,
        c.metrics.share_above_10pct);
  }
  // The 2015 paper's ordering (Fig. 6): MSM 64 leaks less than VSM, 0.0141 against 0.0147
  // (measured; the margin, 4%, is what VSM's bleeding under the plate, where the column's shadow lies
  // in the plate's, adds to the leaking both have at the filtered edges).
  EXPECT_LT(leaking.at("msm-hamburger-64"), 0.99 * leaking.at("vsm-32"));
}

// A bare 4 m ground 0.5 m below a point light of 25 m range (the street's lamps'), nothing to cast
// a shadow: every lit pixel the tracer sees is fully visible. The map rounds distance / range to
// 16-bit steps of 0.38 mm; a depth bias that only grew with the texel's world size (2e-5 of the
// face's width, 0.04 mm at 1 m) stayed below half a step this near the light, and the depth-based
// techniques shadowed the ground in rings of equal distance (over-darkening 0.1734 plain, 0.0313 PCF,
// measured); with the bias in [0,1] depth as well, 0 (measured). The bound: 0.002.
TEST_F(LocalLightsRenderTest, DepthTechniquesDoNotShadowABareGroundNearAPointLightOfLongRange) {
  const scene::Scene scene = scene::load_scene_json(R"({"msm_scene": 1,
    "camera": {"position": [0.3, 2.5, 2.5], "target": [0, 0, 0], "fov_y_deg": 55},
    "lights": [{"type": "point", "position": [0, 0.5, 0], "range": 25, "intensity": [1, 1, 1]}],
    "objects": [{"primitive": {"type": "plane", "size": [4, 4]}}]})",
                                                    std::filesystem::current_path(), "ground.json");
  constexpr int width = 128, height = 96;
  const reference::Result truth =
      reference::render(scene, test::reference_settings(reference::Effect::hard, width, height, 1));
  const image::Image mask = truth.visibility.channel("background");
  Renderer renderer(ctx(), scene);
  for (const std::string technique : {"plain", "pcf"}) {
    RenderSettings s = test::render_settings(technique, width, height, 256);
    s.msaa = 4;
    const RenderResult result = renderer.render(s);
    image::Tolerances tolerances;
    tolerances.max_over_darkening = 0.002;
    image::CompareResult c = image::compare(
        result.shadow.channel("visibility"), truth.visibility.channel("visibility"), tolerances,
        {.metrics = {.mask = &mask}, .failure_dir = "test-failures/local-lights/ground-near-point-" + technique});
    EXPECT_TRUE(c.passed) << technique << ": " << c.report;
    fmt::print("bare ground near a point light, {:<5}: over-darkening {:.4f}, MAE {:.4f}\n", technique,
               c.metrics.over_darkening, c.metrics.mae);
  }
}

// A cylinder of 16 flat facets under a point light of 25 m range (the street's lamps'), lit at
// every incidence across its side. Its vertex normals are the round cylinder's: across a facet the
// interpolated normal turns by up to 11.25 degrees off the facet's, and a receiver plane taken from
// it sloped by that angle over cos² of the incidence off the facet the map holds, which put the
// texels beside a lit receiver in front of its plane. Over-darkening of the cylinder's side against
// the ray tracer, with the receiver plane from the interpolated normal: 0.1263 PCF (deferred), 0.1685
// plain (forward); from the triangle's normal, 0.0164 (the contact with the ground, where PCF's
// kernel reaches the ground in front of the cylinder's foot) and 0.0029 (measured). The bound:
// 1.25x that, at least 0.002 more.
TEST_F(LocalLightsRenderTest, DepthTechniquesDoNotShadowTheLitFacetsOfACylinderUnderAPointLight) {
  const scene::Scene scene = test::faceted_cylinder_scene(
      R"({"type": "point", "position": [1.6, 1.5, 0.8], "range": 25, "intensity": [4, 4, 4]})");
  constexpr int width = 160, height = 120;
  const reference::Result truth =
      reference::render(scene, test::reference_settings(reference::Effect::hard, width, height, 1));
  const image::Image not_cylinder = test::all_but_object(truth.surface.channel("object"), test::kFacetedCylinderObject);
  Renderer renderer(ctx(), scene);
  const std::pair<const char*, double> measured[] = {{"pcf", 0.0164}, {"plain", 0.0029}};
  for (const auto& [technique, over_darkening] : measured) {
    RenderSettings s = test::render_settings(technique, width, height, 256);
    s.msaa = 4;
    const RenderResult result = renderer.render(s);
    image::Tolerances tolerances;
    tolerances.max_over_darkening = std::max(1.25 * over_darkening, over_darkening + 0.002);
    tolerances.max_light_leaking = 0.002; // none leaks on the side (measured 0): over-darkening is the error
    tolerances.max_mae = image::Tolerances::none;
    tolerances.max_share_above_3pct = image::Tolerances::none;
    image::CompareResult c =
        image::compare(result.shadow.channel("visibility"), truth.visibility.channel("visibility"), tolerances,
                       {.metrics = {.mask = &not_cylinder},
                        .failure_dir = std::string("test-failures/local-lights/facets-") + technique});
    EXPECT_TRUE(c.passed) << technique << ": " << c.report;
    EXPECT_GT(c.metrics.pixels, 1500u) << technique;
    msm::test::record_figure(std::string("light.point.facets.") + technique + ".over_darkening",
                             c.metrics.over_darkening,
                             {.below = tolerances.max_over_darkening,
                              .meaning = std::string("point light over a 16-facet cylinder, ") + technique +
                                         ": over-darkening of its side against the traced hard shadow"});
    fmt::print("cylinder of 16 facets under a point light, {:<5}: over-darkening {:.4f}, MAE {:.4f}\n", technique,
               c.metrics.over_darkening, c.metrics.mae);
    // The deferred pass (PCF's default) reads the triangle's normal the surfaces pass stored, the
    // forward pass (the plain map's) takes it from its own derivatives: the same visibility
    // (measured: bit for bit).
    const double worst = test::forward_deferred_difference(renderer, s);
    EXPECT_LE(worst, 1e-6) << technique << ": forward and deferred shading differ";
    fmt::print("  forward against deferred shading: largest difference {}\n", worst);
  }
}

// The 64-bit non-linear map's bilinear lookup (msm_nl_bilinear) on the ground near a point light:
// the light 1 m over a plane, its range 20 m ([-1,1] depths near -0.9), a low wall beside it. Where
// msm-hamburger-128's bilinear lookup has the ground lit (visibility at least 0.98), msm-nl64's is
// no more than 0.05 darker on any of them (32173). Measured: at most 0.012; with the interpolated
// moments taken about depth 0, 52 pixels were darker by more than 0.05, up to 0.67 (isolated dark
// texels).
TEST_F(LocalLightsRenderTest, NonLinear64BilinearLookupLeavesTheGroundNearAPointLightLit) {
  const scene::Scene scene = scene::load_scene_json(R"({"msm_scene": 1,
    "camera": {"position": [1, 3, 2], "target": [1, 0, 0.7], "fov_y_deg": 50},
    "lights": [{"type": "point", "position": [0, 1, 0], "range": 20, "intensity": [10, 10, 10]}],
    "objects": [{"primitive": {"type": "plane", "size": [8, 8]}},
                {"primitive": {"type": "box", "size": [3, 0.5, 0.05]}, "transform": {"translate": [1.6, 0.25, 0.5]}}]})",
                                                    std::filesystem::current_path(), "ground.json");
  Renderer renderer(ctx(), scene);
  auto shadow = [&](const char* technique) {
    RenderSettings s = test::render_settings(technique, 320, 180, 128);
    s.lookup = RenderSettings::Lookup::bilinear;
    return renderer.render(s).shadow;
  };
  const image::Image reference = shadow("msm-hamburger-128"), nl64 = shadow("msm-nl64");
  const int visibility = reference.find_channel("visibility"), background = reference.find_channel("background");
  int lit = 0, dark = 0;
  float worst = 0.0f;
  for (int y = 0; y < reference.height(); ++y)
    for (int x = 0; x < reference.width(); ++x) {
      if (reference.at(x, y, background) > 0.5f || reference.at(x, y, visibility) < 0.98f) continue;
      const float darker = reference.at(x, y, visibility) - nl64.at(x, y, visibility);
      ++lit;
      dark += darker > 0.05f ? 1 : 0;
      worst = std::max(worst, darker);
    }
  fmt::print("ground near a point light, msm-nl64 (bilinear) on msm-hamburger-128's lit pixels ({}): {} darker by "
             "more than 0.05, at most {:.3f}\n",
             lit, dark, worst);
  EXPECT_GE(lit, 10000);
  EXPECT_EQ(dark, 0);
}

// Per pixel of the ground (object 0 of point_scene), the texels of a 90-degree face of
// kPointShadowSize between the point it sees and the nearest seam of the light's cube; NaN
// elsewhere.
std::vector<float> seam_texels(const scene::Scene& scene, const reference::Result& truth) {
  const int object = truth.surface.find_channel("object");
  const glm::mat4 inverse_vp =
      glm::inverse(scene.camera_view_projection(float(kPointImageWidth) / float(kPointImageHeight)));
  const glm::vec3 light = scene.local_lights.at(0).position;
  std::vector<float> texels(size_t(kPointImageWidth * kPointImageHeight), NAN);
  for (int y = 0; y < kPointImageHeight; ++y)
    for (int x = 0; x < kPointImageWidth; ++x) {
      if (truth.surface.at(x, y, object) != 0.0f) continue;
      const glm::vec2 ndc((float(x) + 0.5f) / float(kPointImageWidth) * 2.0f - 1.0f,
                          (float(y) + 0.5f) / float(kPointImageHeight) * 2.0f - 1.0f);
      const glm::vec4 a = inverse_vp * glm::vec4(ndc, 0.0f, 1.0f), b = inverse_vp * glm::vec4(ndc, 1.0f, 1.0f);
      const glm::vec3 o = glm::vec3(a) / a.w, d = glm::vec3(b) / b.w - o;
      const glm::vec3 to_ground = o + d * (-o.y / d.y) - light; // the plane y = 0
      const int face = msm_cube_face(to_ground);
      texels[size_t(y * kPointImageWidth + x)] =
          msm_cube_face_seam_texels(msm_cube_face_uv(to_ground, face), 1.0f, float(kPointShadowSize));
    }
  return texels;
}

// point_scene turned by 0 and 45 degrees about the light, each with its ray-traced truth and the
// texels from each ground pixel to the nearest seam (seam_texels).
struct TurnedPointScene {
  scene::Scene scene;
  reference::Result truth;
  std::vector<float> seam;
};
std::vector<TurnedPointScene> turned_point_scenes(float radius, float range, const reference::Settings& traced) {
  std::vector<TurnedPointScene> turns;
  for (float turn : {0.0f, 45.0f}) {
    scene::Scene s = point_scene(turn, radius, range);
    reference::Result truth = reference::render(s, traced);
    std::vector<float> seam = seam_texels(s, truth);
    turns.push_back({std::move(s), std::move(truth), std::move(seam)});
  }
  return turns;
}

// |visibility - truth| per pixel; every visibility finite.
std::vector<float> visibility_error(const image::Image& visibility, const image::Image& truth) {
  std::vector<float> e(size_t(kPointImageWidth * kPointImageHeight));
  for (int y = 0; y < kPointImageHeight; ++y)
    for (int x = 0; x < kPointImageWidth; ++x) {
      EXPECT_TRUE(std::isfinite(visibility.at(x, y))) << "at " << x << ", " << y;
      e[size_t(y * kPointImageWidth + x)] = std::abs(visibility.at(x, y) - truth.at(x, y));
    }
  return e;
}

// For each turn a of the two, the MAE within 2 texels of a seam (on pixels more than 4 texels from
// every seam in the other turn) is asserted no higher than the same pixels' in the other turn (up
// to paired_standard_errors times the standard error of the pixels' paired differences), nor than
// elsewhere's (pixels more than 4 texels from a seam) up to twice its standard error, and recorded
// as `figure`.turned0 / .turned45.
void expect_seam_error_no_higher(const std::vector<TurnedPointScene>& turns,
                                 const std::vector<std::vector<float>>& error, const std::string& label,
                                 const std::string& figure, const std::string& light = "point light",
                                 double paired_standard_errors = 0.0) {
  for (std::size_t a = 0; a < 2; ++a) {
    const std::size_t b = 1 - a;
    double near_seam = 0, near_seam_squares = 0, same_pixels_turned = 0, paired_squares = 0, elsewhere = 0;
    std::size_t n = 0, n_elsewhere = 0;
    for (std::size_t i = 0; i < error[a].size(); ++i) {
      const float here = turns[a].seam[i], there = turns[b].seam[i];
      if (!(here >= 0.0f) || !(there >= 0.0f)) continue; // not the ground in both
      if (here <= 2.0f && there > 4.0f) {
        near_seam += error[a][i];
        near_seam_squares += double(error[a][i]) * error[a][i];
        same_pixels_turned += error[b][i];
        paired_squares += double(error[a][i] - error[b][i]) * (error[a][i] - error[b][i]);
        ++n;
      } else if (here > 4.0f) {
        elsewhere += error[a][i];
        ++n_elsewhere;
      }
    }
    near_seam /= double(n);
    same_pixels_turned /= double(n);
    elsewhere /= double(n_elsewhere);
    // The pixels near a seam are other pixels than those elsewhere, a few hundred of them: their
    // mean is compared with elsewhere's up to twice its standard error (the same pixels turned
    // pair by pair). Without the guard band the seams' error was 3 to 12 times elsewhere's.
    const double standard_error =
        std::sqrt(std::max(0.0, near_seam_squares / double(n) - near_seam * near_seam) / double(n));
    const double paired_mean = near_seam - same_pixels_turned;
    const double paired_standard_error =
        std::sqrt(std::max(0.0, paired_squares / double(n) - paired_mean * paired_mean) / double(n));
    fmt::print("point, {}, turned {:>2}: MAE within 2 texels of a seam {:.4f} ({} pixels, standard error {:.4f}), the "
               "same pixels turned {:.4f}, elsewhere {:.4f}\n",
               label, a == 0 ? 0 : 45, near_seam, n, standard_error, same_pixels_turned, elsewhere);
    EXPECT_GT(n, 300u) << label;
    EXPECT_LE(near_seam, same_pixels_turned + paired_standard_errors * paired_standard_error)
        << label << ", turned " << a << " (paired standard error " << paired_standard_error << ")";
    EXPECT_LE(near_seam, elsewhere + 2.0 * standard_error) << label << ", turned " << a;
    msm::test::record_figure(
        fmt::format("{}.turned{}.near_seam_mae", figure, a == 0 ? 0 : 45), near_seam,
        {.below = elsewhere + 2.0 * standard_error,
         .meaning = light + ": MAE within 2 texels of a cube seam (bound: elsewhere's + twice its standard error)"});
  }
}

// PCF under a spot and under a point light against the ray tracer's filtered effect (the same
// kernel over each light's own map, reference.h) and against its hard shadow: PCF is the filtered
// truth up to its depth bias, normal offset and discretization, so it is closer to that than to the
// hard shadow. MAE against the filtered truth measured on lavapipe (spot, point; against the hard
// truth 0.0037 and 0.0239, five and eight times more); the bound is 1.25x that, at least 0.002 more.
// The truth's 128 samples add 0.0001 and 0.0003 (0.0006 and 0.0025 at 1024); the rest is the
// renderer's biases and discrete map and, for the point light, its faces' guard band (its texel
// a few per cent wider than the 90-degree face's).
const double kPcfFilteredMeasuredMae[] = {0.0007, 0.0028};

TEST_F(LocalLightsRenderTest, PcfUnderSpotAndPointLightsIsCloserToTheFilteredTruthThanToTheHard) {
  struct Case {
    const char* light;
    scene::Scene scene;
    RenderSettings settings;
  };
  const Case cases[] = {{"spot", spot_scene(), spot_settings("pcf")}, {"point", point_scene(), point_settings("pcf")}};
  for (int i = 0; i < 2; ++i) {
    const Case& c = cases[i];
    SCOPED_TRACE(c.light);
    reference::Settings r =
        test::reference_settings(reference::Effect::filtered, c.settings.width, c.settings.height, 128);
    r.shadow_size = c.settings.shadow_size;
    r.filter_size = c.settings.filter_size;
    r.filter_sigma = c.settings.filter_sigma;
    const reference::Result filtered = reference::render(c.scene, r);
    r.effect = reference::Effect::hard;
    const reference::Result hard = reference::render(c.scene, r);
    const image::Image mask = filtered.visibility.channel("background");
    Renderer renderer(ctx(), c.scene);
    const image::Image pcf = renderer.render(c.settings).shadow.channel("visibility");
    image::Tolerances tolerances;
    tolerances.max_mae = std::max(1.25 * kPcfFilteredMeasuredMae[i], kPcfFilteredMeasuredMae[i] + 0.002);
    tolerances.max_share_above_3pct = 1.0; // the MAE bounds the error
    tolerances.max_share_above_10pct = 1.0;
    const image::CompareResult to_filtered = image::compare(
        pcf, filtered.visibility.channel("visibility"), tolerances,
        {.metrics = {.mask = &mask}, .failure_dir = std::string("test-failures/local-lights/pcf-filtered-") + c.light});
    const image::Metrics to_hard = image::compute_metrics(pcf, hard.visibility.channel("visibility"), {.mask = &mask});
    EXPECT_TRUE(to_filtered.passed) << to_filtered.report;
    EXPECT_LT(to_filtered.metrics.mae, to_hard.mae);
    msm::test::record_figure(std::string("light.") + c.light + ".pcf.filtered_truth.mae", to_filtered.metrics.mae,
                             {.below = tolerances.max_mae,
                              .meaning = std::string(c.light) + " light, pcf: MAE of visibility against the traced "
                                                                "filtered shadow"});
    msm::test::record_figure(std::string("light.") + c.light + ".pcf.filtered_truth_vs_hard", to_filtered.metrics.mae,
                             {.below = to_hard.mae,
                              .meaning = std::string(c.light) + " light, pcf: MAE against the filtered truth, below "
                                                                "its MAE against the hard truth"});
    fmt::print("{}, pcf: MAE against the filtered truth {:.4f}, against the hard truth {:.4f}\n", c.light,
               to_filtered.metrics.mae, to_hard.mae);
  }
}

// Blurred and unblurred, the error against the ray tracer within 2 texels of a seam of the cube is
// no higher than the error at the same pixels with the scene turned by 45 degrees about the light
// (the same image, the seams elsewhere), nor than the error elsewhere on the ground: the guard band
// lets the blur and the lookups filter across the seams as across any texel. Measured (MAE near the
// seams, the same pixels turned, elsewhere; unturned, then turned): PCF unblurred 0.0106, 0.0304,
// 0.0127; 0.0136, 0.0202, 0.0161; 9 taps 0.0088, 0.0298, 0.0247; 0.0215, 0.0257, 0.0268. VSM 32
// unblurred 0.0048, 0.0094, 0.0139; 0.0130, 0.0207, 0.0136; 9 taps 0.0098, 0.0130, 0.0277; 0.0248,
// 0.0318, 0.0275. MSM 64 unblurred 0.0092, 0.0115, 0.0171; 0.0132, 0.0209, 0.0166; 9 taps 0.0219,
// 0.0307, 0.0393; 0.0258, 0.0336, 0.0400. The texels near a seam are finer (a face's texel
// subtends half the angle at its edge that it does at its centre) and their lookups read finer mips
// (msm_cube_face_max_lod), so the seams' error is lower, not only no higher.
TEST_F(LocalLightsRenderTest, PointLightErrorAlongCubeSeamsIsNoHigherThanElsewhere) {
  const std::vector<TurnedPointScene> turns =
      turned_point_scenes(0.0f, 10.0f,
                          test::reference_settings(reference::Effect::hard, kPointImageWidth, kPointImageHeight,
                                                   reference::Settings{}.samples));
  for (const char* technique : {"pcf", "vsm-32", "msm-hamburger-64"})
    for (int taps : {1, 9}) {
      std::vector<std::vector<float>> error;
      for (const TurnedPointScene& t : turns) {
        Renderer renderer(ctx(), t.scene);
        RenderSettings s = point_settings(technique);
        s.filter_size = taps;
        error.push_back(visibility_error(renderer.render(s).shadow.channel("visibility"),
                                         t.truth.visibility.channel("visibility")));
      }
      expect_seam_error_no_higher(turns, error, fmt::format("{:<16} {} taps", technique, taps),
                                  fmt::format("light.point.seams.{}.taps{}", technique, taps));
    }
}

// ---- Soft shadows of a point light of some radius ----
// point_scene's light as a sphere of radius R, its range 6 m (the ground's far corners are 5.74 m
// from it: the maps' depths, distance / range, use most of [0, 1]). The columns' edges, 0.6 m from
// the light, cast penumbrae 2 R (r_f - r_b) / r_b wide (similar triangles): with R = 5 cm about
// 0.2 m on the ground 1.5 m out, up to 11 texels of a face's map on each side, within a 27-texel
// kernel; they cross the seams where the bottom face meets the side faces and run along the one
// between two side faces (the column at 45 degrees, unturned).
constexpr float kSoftPointRadius = 0.05f, kSoftPointRange = 6.0f;

RenderSettings soft_point_settings(std::string technique, int kernel) {
  RenderSettings s = test::render_settings(std::move(technique), kPointImageWidth, kPointImageHeight, kPointShadowSize);
  s.soft_kernel = kernel;
  return s;
}

reference::Settings soft_point_traced() {
  return test::reference_settings(reference::Effect::soft, kPointImageWidth, kPointImageHeight, 64);
}

// MAE of each soft technique's visibility against the ray tracer's soft shadow of the point light
// of radius 5 cm, measured on lavapipe; the bound is 1.25x that, at least 0.002 more. As with the
// spot: CSSM's series leaves the umbrae grey (its leaking, 0.05-0.06, is nearly all its error) and
// VSSM leaks (Chebyshev's bound); PCSS's error is mostly over-darkening (0.0226 of its 0.0300).
struct SoftPointExpectation {
  double mae;
  bool beats_hard_shadows; // closer to the ray tracer than PCF's hard shadow
};
const std::map<std::string, SoftPointExpectation> kSoftPointMeasured = {
    {"pcss", {0.0300, true}}, {"mssm4", {0.0112, true}},  {"mssm6", {0.0235, true}},
    {"vssm", {0.0351, true}}, {"cssm8", {0.0606, false}}, {"cssm16", {0.0541, false}}};

// Every soft technique with the point light of radius 5 cm against the ray-traced sphere: its MAE,
// the hard PCF's beaten by those that do, no NaN; four moments leak less than two (VSSM).
TEST_F(LocalLightsRenderTest, PointLightSoftShadowsAgreeWithTheRayTracer) {
  const scene::Scene scene = point_scene(0.0f, kSoftPointRadius, kSoftPointRange);
  const reference::Result truth = reference::render(scene, soft_point_traced());
  const image::Image mask = truth.visibility.channel("background");
  const image::Image truth_visibility = truth.visibility.channel("visibility");
  Renderer renderer(ctx(), scene);
  const image::Metrics hard = image::compute_metrics(
      renderer.render(soft_point_settings("pcf", 27)).shadow.channel("visibility"), truth_visibility, {.mask = &mask});
  std::map<std::string, double> leaking;
  for (const Technique* tp : rendered_techniques()) {
    const std::string technique(tp->name);
    if (!msm_technique_is_area_light(tp->id)) continue;
    ASSERT_TRUE(kSoftPointMeasured.count(technique)) << technique << " has no measured error";
    const SoftPointExpectation& measured = kSoftPointMeasured.at(technique);
    const RenderResult result = renderer.render(soft_point_settings(technique, 27));
    image::Tolerances tolerances;
    tolerances.max_mae = std::max(1.25 * measured.mae, measured.mae + 0.002);
    tolerances.max_share_above_3pct = 1.0;
    tolerances.max_share_above_10pct = 1.0;
    const image::CompareResult c = image::compare(
        result.shadow.channel("visibility"), truth_visibility, tolerances,
        {.metrics = {.mask = &mask}, .failure_dir = "test-failures/local-lights/soft-point-" + technique});
    fmt::print("soft point, {:<7} vs ray traced: MAE {:.4f} (pcf {:.4f}), leaking {:.4f}, over-darkening {:.4f}\n",
               technique, c.metrics.mae, hard.mae, c.metrics.light_leaking, c.metrics.over_darkening);
    leaking[technique] = c.metrics.light_leaking;
    EXPECT_TRUE(c.passed) << technique << ": " << c.report;
    msm::test::record_figure("light.point_soft." + technique + ".mae", c.metrics.mae,
                             {.below = tolerances.max_mae,
                              .meaning = "point light of radius 5 cm among columns, " + technique +
                                         ": MAE of visibility against the traced soft shadow"});
    EXPECT_EQ(c.metrics.non_finite_in_test, 0u) << technique;
    EXPECT_EQ(image::compute_metrics(result.color, truth.radiance).non_finite_in_test, 0u) << technique;
    if (measured.beats_hard_shadows) { EXPECT_LT(c.metrics.mae, hard.mae) << technique; }
  }
  EXPECT_LT(leaking.at("mssm4"), 0.5 * leaking.at("vssm")); // measured 0.0080 against 0.0298
}

// MSSM4's soft shadow of a point light of radius 15 cm with a 47-texel kernel (search and filter
// regions up to 23 texels on each side of the lookup, three times the hard filters' guard band of
// 8 texels, so that a region cut at a face's edge would show): its error within 2 texels of a
// seam no higher than elsewhere (up to twice the near pixels' standard error, as the hard test)
// nor than at the same pixels turned 45 degrees, up to twice the standard error of the pixels'
// paired differences: turned, a shadow is also seen by another face at another angle to its axes,
// along which the tables' boxes filter (a box's penumbra is up to √2 wider across an edge at 45°
// to them), so unlike the hard filters' the soft error differs turned even without seams.
// Measured (near the seams, the same pixels turned, elsewhere): unturned 0.0605, 0.0753, 0.0579;
// turned 0.0654, 0.0659, 0.0613 (with 256 traced samples per pixel turned 0.0650 against 0.0631 the
// same pixels turned: within the paired error). With the guard band of the hard filters (8 texels)
// the search and filter regions were cut at the map's edge near a seam and the test failed: 0.0832,
// 0.0669, 0.0488; 0.0947, 0.0582, 0.0516.
TEST_F(LocalLightsRenderTest, PointLightSoftErrorAlongCubeSeamsIsNoHigherThanElsewhere) {
  const std::vector<TurnedPointScene> turns = turned_point_scenes(0.15f, kSoftPointRange, soft_point_traced());
  std::vector<std::vector<float>> error;
  for (const TurnedPointScene& t : turns) {
    Renderer renderer(ctx(), t.scene);
    error.push_back(visibility_error(renderer.render(soft_point_settings("mssm4", 47)).shadow.channel("visibility"),
                                     t.truth.visibility.channel("visibility")));
  }
  expect_seam_error_no_higher(turns, error, "mssm4, radius 15 cm", "light.point_soft.seams.mssm4",
                              "point light of radius 15 cm, mssm4", /*paired_standard_errors=*/2.0);
}

// The ground of point_scene lit by the point light once, not once per cube face: at a point seen
// by the bottom face (-0.3, 0, 0.3) and one seen by the +x face (1.6, 0, -0.9), both outside every
// shadow, E cos θ = I / d² · h / d worked out by hand (1.5 W/sr; d² = 1.18 and 4.37: 1.1702 and
// 0.1642 W/m²), so the colour is the Lambertian albedo / π times it plus the ambient, tone mapped;
// the 8-bit target rounds by less than 2%.
TEST_F(LocalLightsRenderTest, PointLightIrradianceIsIntensityOverDistanceSquaredTimesTheCosine) {
  const scene::Scene scene = point_scene();
  const RenderSettings s = point_settings("msm-hamburger-64");
  Renderer renderer(ctx(), scene);
  const RenderResult result = renderer.render(s);
  const glm::mat4 vp = scene.camera_view_projection(float(kPointImageWidth) / float(kPointImageHeight));
  const glm::vec3 albedo = scene.materials.at(scene.objects.at(0).material).albedo;
  for (const auto& [p, irradiance] :
       {std::pair(glm::vec3(-0.3f, 0.0f, 0.3f), 1.1702f), std::pair(glm::vec3(1.6f, 0.0f, -0.9f), 0.1642f)}) {
    const glm::vec4 clip = vp * glm::vec4(p, 1.0f);
    const glm::vec2 ndc = glm::vec2(clip) / clip.w;
    const int x = int(std::floor((ndc.x * 0.5f + 0.5f) * float(kPointImageWidth)));
    const int y = int(std::floor((ndc.y * 0.5f + 0.5f) * float(kPointImageHeight)));
    ASSERT_TRUE(x >= 0 && x < kPointImageWidth && y >= 0 && y < kPointImageHeight) << x << ", " << y;
    const glm::vec3 expected = msm_aces(albedo * (irradiance / float(M_PI) + MSM_AMBIENT) * s.exposure);
    EXPECT_NEAR(result.shadow.at(x, y, result.shadow.find_channel("visibility")), 1.0f, 1e-3f) << p.x;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(result.color.at(x, y, c), expected[c], 0.02f * expected[c]) << p.x << ", " << c;
  }
}

// Scattering with point lights is refused by name, and so is a soft kernel whose guard band would
// take more than a quarter of a face's map (27 texels wide at 64² per face), never drawn without them.
TEST_F(LocalLightsRenderTest, PointLightsWithScatteringTooWideAGuardBandOrWithoutRangeAreRefused) {
  {
    Renderer renderer(ctx(), point_scene());
    try {
      renderer.render(point_settings("scatter-march-32"));
      ADD_FAILURE() << "no RenderError for scattering with a point light";
    } catch (const RenderError& e) { EXPECT_NE(std::string(e.what()).find("point"), std::string::npos) << e.what(); }
    RenderSettings s = test::render_settings("mssm4", 64, 48, 64);
    s.soft_kernel = 27;
    try {
      renderer.render(s);
      ADD_FAILURE() << "no RenderError for a soft kernel of 27 at 64² per face";
    } catch (const RenderError& e) {
      EXPECT_NE(std::string(e.what()).find("guard band"), std::string::npos) << e.what();
    }
    s.shadow_size = 128; // the band, 17 texels, fits
    EXPECT_NO_THROW(renderer.render(s));
  }
  Renderer renderer(ctx(), scene_with_lights(R"({"type": "point", "position": [0, 3, 0]})"));
  try {
    renderer.render(point_settings("pcf"));
    ADD_FAILURE() << "no RenderError for a point light without range";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("point light without \"range\""), std::string::npos) << e.what();
  }
}

// A spot 3 m from the ground's centre at 45° incidence (its axis through the centre, the map's up
// the world's y), over a 4 m ground with a 0.5 m box beside the centre (towards the light: its
// shadow falls on the ground in view). The incidence is where a map's depth changes fastest across a
// texel, so where the MSAA samples' depths must be taken at their own positions.
const glm::vec3 kObliqueSpot(0.0f, 2.1213f, 2.1213f);
constexpr float kObliqueRange = 10.0f, kObliqueOuterDeg = 40.0f;

scene::Scene oblique_spot_scene(bool occluder) {
  return scene::load_scene_json(fmt::format(R"({{"msm_scene": 1,
    "camera": {{"position": [3, 3, 3], "target": [0, 0, 0], "fov_y_deg": 45}},
    "lights": [{{"type": "spot", "position": [{}, {}, {}], "direction": [0, -1, -1], "inner_cone_deg": 35,
                 "outer_cone_deg": {}, "range": {}, "intensity": [9, 9, 9]}}],
    "objects": [{{"primitive": {{"type": "plane", "size": [4, 4]}}}}{}]}})",
                                            kObliqueSpot.x, kObliqueSpot.y, kObliqueSpot.z, kObliqueOuterDeg,
                                            kObliqueRange,
                                            occluder ? R"(, {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]},
                                  "transform": {"translate": [0, 0.25, 0.6]}})"
                                                     : ""),
                                std::filesystem::current_path(), "oblique_spot.json");
}

// The spot map's depth at every MSAA sample is the radial distance / range of the ground seen at
// that sample's standard position (Vulkan's sample locations, the positions PCF's receiver plane
// takes them at): the ray through the position, from the map's frustum (docs/techniques.md, "Light
// kinds": a perspective map over the outer cone), meets the ground plane y = 0. The map rounds to
// 16 bits (steps of 1.5e-5).
TEST_F(LocalLightsRenderTest, SpotMapSampleDepthsAreRadialDistancesAtTheStandardSamplePositions) {
  if (!ctx().properties().limits.standardSampleLocations) GTEST_SKIP() << "no standard sample locations";
  constexpr int size = 128;
  RenderSettings s = test::render_settings("pcf", 64, 48, size);
  s.msaa = 4;
  Renderer renderer(ctx(), oblique_spot_scene(false));
  Intermediates in;
  RendererInternals::render(renderer, s, in);
  ASSERT_EQ(in.depth_samples.size(), size_t(size * size * 4));
  const glm::vec3 axis = glm::normalize(glm::vec3(0.0f, -1.0f, -1.0f));
  const glm::mat4 map_to_world =
      glm::inverse(glm::perspective(2.0f * glm::radians(kObliqueOuterDeg), 1.0f, 0.01f, kObliqueRange) *
                   glm::lookAt(kObliqueSpot, kObliqueSpot + axis, glm::vec3(0.0f, 1.0f, 0.0f)));
  // Radial distance / range of the ground at map position (x, y) in texels (y down the map);
  // negative where the ray misses the ground.
  auto ground_depth = [&](double x, double y) {
    const glm::vec4 ndc(float(2.0 * x / size - 1.0), float(2.0 * y / size - 1.0), 0.0f, 1.0f);
    const glm::vec4 far = map_to_world * glm::vec4(glm::vec2(ndc), 1.0f, 1.0f);
    const glm::dvec3 direction = glm::normalize(glm::dvec3(glm::vec3(far) / far.w) - glm::dvec3(kObliqueSpot));
    if (direction.y >= 0.0) return -1.0;
    return (-double(kObliqueSpot.y) / direction.y) / double(kObliqueRange);
  };
  const double positions[4][2] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
  double sum = 0, worst = 0;
  int counted = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int k = 0; k < 4; ++k) {
        const double expected = ground_depth(x + positions[k][0], y + positions[k][1]);
        const float stored = in.depth_samples[size_t((y * size + x) * 4 + k)];
        // On the ground (4 m: not every sample sees it) and short of the range.
        if (expected < 0.0 || expected > 0.9 || stored >= 0.9f) continue;
        const double error = std::abs(double(stored) - expected);
        sum += error;
        worst = std::max(worst, error);
        ++counted;
      }
  ASSERT_GT(counted, size * size); // a quarter of the map's samples at least
  // Rounding to the nearest 16-bit step errs by at most half a step (7.6e-6), by a quarter step
  // (3.8e-6) on average; measured on lavapipe: mean 3.8e-6, largest 8.2e-6 (depths taken a third of
  // their slope across the texel off the standard positions erred by 1.4e-4 on average, 1.7e-3 at most).
  EXPECT_LT(sum / counted, 6e-6) << counted << " samples";
  EXPECT_LT(worst, 1e-5) << counted << " samples";
  fmt::print("spot map sample depths against the radial distance: mean error {:.2e}, largest {:.2e} ({} samples)\n",
             sum / counted, worst, counted);
}

// The depth-map techniques with MSAA 4 under the oblique spot against the ray tracer's hard
// shadow: lit ground reads lit (each sample's depth is compared with the receiver plane at the
// sample's own position) and the box's shadow is where the tracer puts it. Measured on lavapipe,
// the bounds that much and a margin above; with the samples' depths off their positions, lit ground
// read as partly shadowed: MAE 0.35 (plain) and 0.18 (PCF), over-darkening of lit ground 0.22 (PCF).
struct ObliqueSpotMeasured {
  const char* technique;
  double mae, lit_over_darkening, share_above_3pct;
};
const ObliqueSpotMeasured kObliqueSpotMeasured[] = {{"plain", 0.0012, 0.0013, 0.0034}, {"pcf", 0.0049, 0.0039, 0.022}};

TEST_F(LocalLightsRenderTest, DepthMapsUnderAnObliqueSpotAgreeWithTheRayTracer) {
  const scene::Scene scene = oblique_spot_scene(true);
  constexpr int width = 160, height = 120;
  const reference::Settings r =
      test::reference_settings(reference::Effect::hard, width, height, reference::Settings{}.samples);
  const reference::Result truth = reference::render(scene, r);
  const image::Image background = truth.visibility.channel("background");
  // Over-darkening of what the tracer sees lit: everything but the lit ground masked.
  image::Image shadowed_or_background = background;
  const image::Image truth_visibility = truth.visibility.channel("visibility");
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (truth_visibility.at(x, y, 0) < 1.0f) shadowed_or_background.at(x, y, 0) = 1.0f;
  Renderer renderer(ctx(), scene);
  for (const ObliqueSpotMeasured& measured : kObliqueSpotMeasured) {
    RenderSettings s = test::render_settings(measured.technique, width, height, 256);
    s.msaa = 4;
    const image::Image visibility = renderer.render(s).shadow.channel("visibility");
    image::Tolerances tolerances;
    tolerances.max_mae = measured.mae + 0.0015;
    tolerances.max_share_above_3pct = measured.share_above_3pct + 0.01;
    const image::CompareResult all =
        image::compare(visibility, truth_visibility, tolerances,
                       {.metrics = {.mask = &background},
                        .failure_dir = "test-failures/local-lights/oblique-spot-" + std::string(measured.technique)});
    EXPECT_TRUE(all.passed) << measured.technique << ": " << all.report;
    const image::Metrics lit = image::compute_metrics(visibility, truth_visibility, {.mask = &shadowed_or_background});
    EXPECT_GT(lit.pixels, size_t(width * height / 4)) << "too little lit ground in view";
    EXPECT_LT(lit.over_darkening, measured.lit_over_darkening + 0.0015)
        << measured.technique << " reads lit ground as shadowed";
    fmt::print("oblique spot, {:<5} vs ray traced: MAE {:.4f}, over-darkening {:.4f}, > 3%: {:.4f}; lit ground's "
               "over-darkening {:.4f} ({} pixels)\n",
               measured.technique, all.metrics.mae, all.metrics.over_darkening, all.metrics.share_above_3pct,
               lit.over_darkening, lit.pixels);
  }
}

} // namespace
} // namespace msm::render
