// Spot and point lights in the renderer: spot lights' shadows (perspective maps of radial depth)
// against the ray tracer's hard shadows per technique, the maps' per-sample depths against the
// radial distance at the standard sample positions, their unshadowed irradiance against a value
// worked out by hand; the light kinds and techniques it does not draw with them are refused with a
// message that names them, never rendered as if they were absent.
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/render/renderer_internals.h"
#include "msm/scene/scene.h"
#include "msm/shading.h"
#include "msm/techniques.h"
#include "msm/test/render_settings.h"

#include "msm/image/metrics.h"
#include "msm/test/image_compare.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

namespace msm::render {
namespace {

class LocalLightsRenderTest : public vk::test::VulkanTest {};

scene::Scene scene_with_lights(const std::string& lights) {
  return scene::load_scene_json(R"({"msm_scene": 1, "lights": [)" + lights + R"(],
    "objects": [{"primitive": {"type": "plane", "size": [4, 4]}},
                {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]}, "transform": {"translate": [0, 0.5, 0]}}]})",
                                std::filesystem::current_path(), "test.json");
}

TEST_F(LocalLightsRenderTest, KindsTheRendererDoesNotDrawAreRefusedByName) {
  for (const scene::LightKindInfo& kind : scene::light_kinds()) {
    if (kind.rendered) continue;
    const std::string light = kind.kind == scene::LightKind::spot
                                  ? R"({"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0]})"
                                  : R"({"type": "point", "position": [0, 3, 0]})";
    // Alone and beside a directional light (which alone would render).
    for (const std::string& lights : {light, R"({"towards_light": [0, 1, 0]}, )" + light}) {
      const scene::Scene s = scene_with_lights(lights);
      try {
        Renderer renderer(ctx(), s);
        ADD_FAILURE() << "no RenderError for a scene with a " << kind.name << " light";
      } catch (const RenderError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(std::string(kind.name)), std::string::npos) << what;
        EXPECT_NE(what.find("msm reference"), std::string::npos) << what;
      }
    }
  }
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
const std::map<std::string, double> kSpotMeasuredMae = {{"plain", 0.0011},
                                                        {"pcf", 0.0037},
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
                                                        {"msm-nl64", 0.0039},
                                                        {"msm-nl32", 0.0140}};

TEST_F(LocalLightsRenderTest, SpotLightShadowsAgreeWithTheRayTracer) {
  const scene::Scene scene = spot_scene();
  reference::Settings r;
  r.effect = reference::Effect::hard;
  r.width = kWidth;
  r.height = kHeight;
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

// What the renderer does not draw with spot lights is refused by name, never drawn without them.
TEST_F(LocalLightsRenderTest, SpotLightsWithSoftShadowsOrWithoutRangeAreRefused) {
  {
    Renderer renderer(ctx(), spot_scene());
    for (const char* technique : {"pcss", "scatter-march-32"}) {
      try {
        renderer.render(spot_settings(technique));
        ADD_FAILURE() << "no RenderError for " << technique << " with a spot light";
      } catch (const RenderError& e) { EXPECT_NE(std::string(e.what()).find("spot"), std::string::npos) << e.what(); }
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
  reference::Settings r;
  r.effect = reference::Effect::hard;
  r.width = width;
  r.height = height;
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
