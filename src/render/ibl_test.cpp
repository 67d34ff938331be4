// Image-based lighting in the renderer against the ray-traced ground truth (Kneiphof
// 2017 §6): the full probe (msm::reference, effect environment) and its extracted area lights
// (--extracted-lights). The orderings of the paper that hold on the built-in probe scenes, asserted
// with margins from the measurements of docs/results.md ("Image-based lighting against the ground
// truth", scripts/ibl-compare.sh): on sky_probe, 32 soft-shadowed area lights are closer to the
// full probe than 256 point lights with hard shadows (on city_probe with its plain cut they are
// not: not asserted there; with the horizon split they are); on both, MSSM6 is closer to the area
// lights than MSSM4 under large lights (16 lights, cones of tens of degrees). The same for
// city_probe's objects under blender-data's interior.exr (both orderings) and courtyard.exr (MSSM6
// against MSSM4 only; docs/results.md, "Image-based lighting on three studio probes"), and the
// models scene under probes (below). Tone-mapped images (the renderer's look), MAE of the
// luminance, background masked.
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/scene/scene.h"
#include "msm/shading.h"

#include "msm/image/metrics.h"
#include "msm/test/figures.h"
#include "msm/test/reference_settings.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

namespace msm::render {
namespace {

class IblTest : public vk::test::VulkanTest {};

constexpr int kWidth = 160, kHeight = 90, kShadowSize = 256;

// The ground truth in the renderer's look (ACES at exposure 1), and its background mask.
struct Truth {
  image::Image look, background;
};

Truth truth(const scene::Scene& scene, bool probe_lights, int samples) {
  reference::Settings rs = test::reference_settings(reference::Effect::environment, kWidth, kHeight, samples);
  rs.probe_lights = probe_lights;
  const reference::Result r = reference::render(scene, rs);
  return {image::tone_map(r.radiance, {0.0, image::ToneCurve::aces}), r.visibility.channel("background")};
}

double mae(const vk::Context& ctx, const scene::Scene& scene, const std::string& technique, const Truth& t) {
  RenderSettings s;
  s.technique = technique;
  s.width = kWidth;
  s.height = kHeight;
  s.shadow_size = kShadowSize;
  Renderer renderer(ctx, scene);
  const image::Metrics m = image::compute_metrics(renderer.render(s).color, t.look, {.mask = &t.background});
  EXPECT_EQ(m.non_finite, 0u) << technique;
  fmt::print("{} {} lights {}: MAE {:.5f}\n", scene.name, scene.probe->lights, technique, m.mae);
  return m.mae;
}

// The built-in scene `name` cut into `count` lights, under its own probe or under `probe` (a file
// that replaces the scene's, as scripts/ibl-compare.sh's PROBE does).
scene::Scene with_lights(const std::string& name, int count, const std::string& probe = "",
                         bool horizon_split = false) {
  scene::Scene s = scene::builtin_scene(name);
  if (!probe.empty()) scene::set_probe(s, probe); // the scene's probe settings kept where it has a probe
  s.probe->horizon_split = horizon_split;
  scene::set_probe_light_count(s, count);
  return s;
}

const std::string kStudioLights = "/usr/share/blender/datafiles/studiolights/world/";

// Measured margins (recorded as ordering.ibl.*): MAE(256 hard point lights) − MAE(32 lights, mssm6) and
// MAE(mssm4) − MAE(mssm6) at 16 lights; asserted at half their measured size. The truth's noise at
// these sample counts moves them far less: over seeds 1-3 the first spread by 6e-5, the second by
// 1e-6 (msm reference and msm compare, 160x90). The studio probes' values are this test's own
// measurements (256-sample truth): under interior.exr the first is 0.0004-0.0005 against
// 1024-sample truths of two seeds (scripts/ibl-compare.sh), a narrow ordering.
// area_over_points 0: not asserted (on city_probe's plain cut, under city.exr and courtyard.exr,
// the 256 point lights are closer, with the rectangles shaded as rectangles at the horizon too).
// The least bias for the receiver's plane (msm_soft_plane_bias, soft.h) lowers MSSM4's MAE more
// than MSSM6's (its bound needs a bias of σ, MSSM6's sqrt(m4/m2)), so the six-over-four margins are
// narrow: the ordering holds everywhere, by little.
// pcss_over_points: the same with the 32 area lights rendered by PCSS, as the paper's Figure 2
// renders them (Kneiphof §6: "the extracted area lights are rendered using PCSS"); measured here
// (256-sample truth): sky_probe 0.01143 − 0.00643, city_probe split 0.00736 − 0.00599, under
// interior.exr 0.00987 − 0.00779; with city.exr's plain cut and under courtyard.exr PCSS loses too,
// not asserted there.
struct Expected {
  double area_over_points, six_over_four, pcss_over_points = 0.0;
};

void check_orderings(const vk::Context& ctx, const std::string& name, const Expected& e,
                     const std::string& probe_file = "", bool horizon_split = false) {
  const std::string under = probe_file.empty() ? "" : "_under_" + std::filesystem::path(probe_file).stem().string();
  const std::string key = "ordering.ibl." + name + under + (horizon_split ? "_horizon_split" : "") + ".";
  const std::string what =
      name + (probe_file.empty() ? "" : " under " + std::filesystem::path(probe_file).filename().string()) +
      (horizon_split ? ", horizon split" : "") + ": ";
  if (e.area_over_points > 0.0 || e.pcss_over_points > 0.0) {
    const Truth probe = truth(with_lights(name, 32, probe_file), false, 256);
    const scene::Scene area_lights = with_lights(name, 32, probe_file, horizon_split);
    const double points = mae(ctx, with_lights(name, 256, probe_file, horizon_split), "msm-hamburger-64", probe);
    if (e.area_over_points > 0.0) {
      const double margin = points - mae(ctx, area_lights, "mssm6", probe);
      EXPECT_GT(margin, 0.5 * e.area_over_points) << name << ": 32 area lights against 256 point lights";
      msm::test::record_figure(key + "hard256_minus_mssm6_32", margin,
                               {.above = 0.5 * e.area_over_points,
                                .meaning = what + "MAE of 256 hard point lights minus 32 area lights' (mssm6)"});
    }
    if (e.pcss_over_points > 0.0) {
      const double margin = points - mae(ctx, area_lights, "pcss", probe);
      EXPECT_GT(margin, 0.5 * e.pcss_over_points) << name << ": 32 area lights (PCSS) against 256 point lights";
      msm::test::record_figure(key + "hard256_minus_pcss_32", margin,
                               {.above = 0.5 * e.pcss_over_points,
                                .meaning = what + "MAE of 256 hard point lights minus 32 area lights' (pcss)"});
    }
  }
  if (e.six_over_four <= 0.0) return;
  const scene::Scene sixteen = with_lights(name, 16, probe_file, horizon_split);
  const Truth lights = truth(sixteen, true, 64);
  const double six = mae(ctx, sixteen, "mssm6", lights), four = mae(ctx, sixteen, "mssm4", lights);
  EXPECT_GT(four - six, 0.5 * e.six_over_four) << name << ": MSSM6 against MSSM4 under 16 large lights";
  msm::test::record_figure(
      key + "mssm4_minus_mssm6_16", four - six,
      {.above = 0.5 * e.six_over_four,
       .meaning = what + "MAE of mssm4 minus mssm6's under 16 lights (against the lights' truth)"});
}

TEST_F(IblTest, SkyProbeOrderings) { check_orderings(ctx(), "sky_probe", {0.0048, 0.0003, 0.0050}); }
TEST_F(IblTest, CityProbeOrderings) { check_orderings(ctx(), "city_probe", {0.0, 0.0010}); }
// city_probe with the horizon split (docs/techniques.md): its 32 area lights beat the 256 point
// lights since the soft techniques take the least bias for the receiver's plane (docs/results.md,
// "The least bias for the receiver's plane"; with JCGT's bias they lose by 0.0007 against
// ibl-compare's 1024-sample truths).
TEST_F(IblTest, CityProbeWithTheHorizonSplitOrderings) {
  check_orderings(ctx(), "city_probe", {0.0006, 0.0009, 0.0013}, "", true);
}
// city_probe's objects under two more of blender-data's probes (docs/results.md, "Image-based
// lighting on three studio probes"): interior.exr (a window-like light of 18% of the energy, 57°
// high), where 32 area lights hold against 256 point lights; courtyard.exr (soft, no light above
// 5% of the energy), where they do not (not asserted there).
TEST_F(IblTest, InteriorProbeOrderings) {
  check_orderings(ctx(), "city_probe", {0.0010, 0.0003, 0.0020}, kStudioLights + "interior.exr");
}
TEST_F(IblTest, CourtyardProbeOrderings) {
  check_orderings(ctx(), "city_probe", {0.0, 0.0011}, kStudioLights + "courtyard.exr");
}

// The models scene (two torus knots above the ground, no probe of its own) lit by probes instead of
// its light (scene::set_probe: 128² faces), docs/results.md "The models scene under probes": 32
// area lights beat 256 hard lights under the sky (by far: the hard lights' sun and sky both sharp)
// and under interior.exr; under city.exr they tie (0.0078 against 0.0077 with 1024-sample truths:
// not asserted) and under courtyard.exr they lose. MSSM6 beats MSSM4 at 16 lights under city.exr
// and interior.exr; under the sky they tie (0.0094 against 0.0095: not asserted).
// Margins: this test's own measurements (0.02269 − 0.00853; 0.01194 − 0.00957 and 0.00983 −
// 0.00945; 0.00927 − 0.00876). With PCSS the 32 lights win under all three, city.exr included
// (0.00895 − 0.00719).
TEST_F(IblTest, ModelsUnderTheSkyOrderings) { check_orderings(ctx(), "models", {0.0142, 0.0, 0.0150}, "sky"); }
TEST_F(IblTest, ModelsUnderInteriorOrderings) {
  check_orderings(ctx(), "models", {0.0024, 0.0004, 0.0032}, kStudioLights + "interior.exr");
}
TEST_F(IblTest, ModelsUnderCityOrderings) {
  check_orderings(ctx(), "models", {0.0, 0.0005, 0.0017}, kStudioLights + "city.exr");
}

// A wide PCSS kernel under many lights keeps the image's brightness. With the light count a
// uniform loop bound, lavapipe recompiles the shading at every bind with the frame's values
// inlined (docs/results.md, "CPU-side costs"), and with 64 lights and a 31-texel kernel the image
// comes out 0.128 darker on average than with 7 (city_probe, 160x90, 256²; under courtyard.exr:
// 0.21). With the count a specialization constant: 0.0002. The cause in
// the driver was not isolated; this holds the result.
TEST_F(IblTest, WidePcssKernelUnderManyLightsKeepsTheBrightness) {
  const scene::Scene scene = with_lights("city_probe", 64);
  Renderer renderer(ctx(), scene);
  auto render_with = [&](int kernel) {
    RenderSettings s;
    s.technique = "pcss";
    s.width = kWidth;
    s.height = kHeight;
    s.shadow_size = kShadowSize;
    s.soft_kernel = kernel;
    return renderer.render(s).color;
  };
  const image::Image narrow = render_with(7), wide = render_with(31);
  const image::Metrics m = image::compute_metrics(wide, narrow);
  EXPECT_EQ(m.non_finite, 0u);
  EXPECT_LT(std::abs(m.mean_error), 0.01) << "mean luminance, 31-texel kernel minus 7-texel kernel";
}

// Sub-lights (the probe's "sub_lights") in the renderer: an unoccluded plane under the sky as one
// light whose unshadowed irradiance is the sum of a 64-region cut's lights looks as under those 64
// lights (one light alone gives this plane 27% too much: msm_reference_environment_test), for a soft
// technique and a hard one; without sub-lights it does not. Mean of the tone-mapped luminance.
TEST_F(IblTest, SubLightsGiveAPlaneTheIrradianceOfTheirFinerCut) {
  auto plane_under_sky = [](int lights, int sub_lights) {
    const std::string json = fmt::format(
        R"({{"msm_scene": 1, "camera": {{"position": [0, 4, 0.01], "target": [0, 0, 0], "fov_y_deg": 40}},
            "probe": {{"file": "sky", "size": 32, "lights": {}, "sub_lights": {}}},
            "objects": [{{"primitive": {{"type": "plane", "size": [20, 20]}}}}]}})",
        lights, sub_lights);
    return scene::load_scene_json(json, std::filesystem::current_path(), "plane.json");
  };
  for (const char* technique : {"mssm6", "msm-hamburger-64"}) {
    auto render = [&](int lights, int sub_lights) {
      RenderSettings s;
      s.technique = technique;
      s.width = 64;
      s.height = 64;
      s.shadow_size = kShadowSize;
      return Renderer(ctx(), plane_under_sky(lights, sub_lights)).render(s).color;
    };
    const image::Image fine = render(64, 0);
    // One light: its sub-lights surround the plane's normal, each is shaded (sub_lights_irradiance's
    // loop); 16 lights: most see their sub-lights all above or all below the plane's horizon (the
    // summary's matrix or nothing).
    for (int lights : {1, 16}) {
      const image::Metrics with = image::compute_metrics(render(lights, 64), fine);
      const image::Metrics without = image::compute_metrics(render(lights, 0), fine);
      fmt::print("{}: {} lights with sub-lights against 64 lights: mean {:+.4f}, MAE {:.4f}; without: mean {:+.4f}\n",
                 technique, lights, with.mean_error, with.mae, without.mean_error);
      EXPECT_EQ(with.non_finite, 0u);
      EXPECT_LT(std::abs(with.mean_error), 0.005) << technique << " " << lights;
      EXPECT_LT(with.mae, 0.002) << technique << " " << lights; // measured 0.0000
      if (lights == 1) { EXPECT_GT(std::abs(without.mean_error), 0.02) << technique; }
    }
  }
}

} // namespace
} // namespace msm::render
