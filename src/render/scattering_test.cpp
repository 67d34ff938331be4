// The scattering techniques in the renderer (JCGT §5): the ray-marched in-scattering of an
// unshadowed medium against the closed form f E (1 − exp(−σt s)) / σt, an occluder's shadow in the
// medium, and the frame without a medium.
#include "msm/render/renderer.h"

#include "msm/scattering.h"
#include "msm/shading.h"
#include "msm/techniques.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <span>
#include <string>

namespace msm::render {
namespace {

class ScatteringTest : public vk::test::VulkanTest {};

// The sky's radiance under the scattering techniques is msm_aces_inverse of the displayed sky:
// a round trip through the tone curve returns every display value in [0, 0.99] within 1e-5.
TEST(AcesInverse, RoundTrip) {
  for (int i = 0; i <= 990; ++i) {
    float y = float(i) / 1000.0f, x = msm_aces_inverse(y);
    EXPECT_GE(x, 0.0f);
    EXPECT_NEAR(msm_aces(x), y, 1e-5f) << y;
  }
}

constexpr int kWidth = 96, kHeight = 64;

// A ground plane (8 x 8 at y = 0) under a light from `towards`, in a forward-scattering medium;
// `wall` adds a wall above the ground whose shadow crosses the view.
scene::Scene medium_scene(bool wall, bool medium = true, glm::vec3 towards = {0.4f, 1.0f, -0.3f}) {
  return scene::load_scene_json(
      fmt::format(R"({{ "msm_scene": 1, "name": "medium",
        "camera": {{ "position": [0, 2.5, 6], "target": [0, 0, 0], "fov_y_deg": 50, "near": 0.1, "far": 20 }},
        "light": {{ "towards_light": [{}, {}, {}], "irradiance": [3, 2.5, 2] }},
        {} "objects": [ {{ "name": "ground", "primitive": {{ "type": "plane", "size": [8, 8] }} }} {} ] }})",
                  towards.x, towards.y, towards.z,
                  medium ? R"("medium": { "extinction": 0.2, "scattering_albedo": 0.8, "phase": "henyey_greenstein",
                                         "g": 0.4 },)"
                         : "",
                  wall ? R"(, { "name": "wall", "primitive": { "type": "box", "size": [3, 3, 0.6] },
                               "transform": { "translate": [0, 1.5, 0] } })"
                       : ""),
      ".", "medium");
}

RenderSettings settings(const std::string& technique) {
  RenderSettings s;
  s.technique = technique;
  s.width = kWidth;
  s.height = kHeight;
  s.shadow_size = 256;
  return s;
}

// Where the view ray of pixel (x, y) meets the ground (y = 0, |x|, |z| < 4 - margin), or nothing.
std::optional<glm::dvec3> ground_hit(const scene::Scene& scene, int x, int y, double margin) {
  glm::dmat4 inverse = glm::inverse(glm::dmat4(scene.camera_view_projection(float(kWidth) / float(kHeight))));
  glm::dvec2 ndc((x + 0.5) / kWidth * 2.0 - 1.0, (y + 0.5) / kHeight * 2.0 - 1.0);
  glm::dvec4 far = inverse * glm::dvec4(ndc, 1.0, 1.0);
  glm::dvec3 origin(scene.camera.position), direction = glm::normalize(glm::dvec3(far) / far.w - origin);
  if (direction.y >= 0.0) return std::nullopt;
  glm::dvec3 hit = origin - direction * (origin.y / direction.y);
  if (std::abs(hit.x) > 4.0 - margin || std::abs(hit.z) > 4.0 - margin) return std::nullopt;
  return hit;
}

// Nothing shadows the medium above the ground (lit from straight above, so that the ground's depth
// is one value per texel: under a tilted light the last samples before the ground can compare
// against a texel's farther-up part of the ground and self-shadow, the acne of hard shadow maps):
// the marched weights sum to ∫₀ˢ exp(−σt t) dt, so
// every pixel sees the whole ray (visible fraction 1 up to float rounding) and the ground's pixels
// the closed form f E (1 − exp(−σt s)) / σt, s from a ray-plane intersection in double. Tolerance
// 1e-4 relative: the distance comes back from the 32-bit depth buffer and the weights sum in float
// over up to 128 terms; measured 1.1e-5 on lavapipe.
TEST_F(ScatteringTest, UnshadowedMediumMatchesTheClosedForm) {
  const scene::Scene scene = medium_scene(false, true, {0.0f, 1.0f, 0.0f});
  Renderer renderer(ctx(), scene);
  const scene::Medium& medium = *scene.medium;
  for (const char* technique : {"scatter-march-32", "scatter-march-128"}) {
    SCOPED_TRACE(technique);
    RenderResult r = renderer.render(settings(technique));
    ASSERT_EQ(r.scattering.width(), kWidth);
    int ground = 0;
    double worst = 0.0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        ASSERT_NEAR(r.scattering.at(x, y, 3), 1.0f, 1e-5f) << x << ", " << y;
        std::optional<glm::dvec3> hit = ground_hit(scene, x, y, 0.05);
        if (!hit) continue;
        glm::dvec3 ray = *hit - glm::dvec3(scene.camera.position);
        double s = glm::length(ray);
        double phase = msm_scattering_phase_term(medium.extinction, medium.scattering_albedo, medium.g,
                                                 scene.light().towards_light, glm::vec3(ray / s));
        double integral = -std::expm1(-double(medium.extinction) * s) / double(medium.extinction);
        for (int c = 0; c < 3; ++c) {
          double expected = phase * double(scene.light().irradiance[c]) * integral;
          double error = std::abs(double(r.scattering.at(x, y, c)) - expected) / expected;
          worst = std::max(worst, error);
          ASSERT_LT(error, 1e-4) << x << ", " << y << " channel " << c << ": " << r.scattering.at(x, y, c) << " vs "
                                 << expected;
        }
        ++ground;
      }
    EXPECT_GT(ground, kWidth * kHeight / 3);
    fmt::print("{}: {} ground pixels, worst relative error {:.2e}\n", technique, ground, worst);
  }
}

// A wall in the light shadows part of the medium: its shadow's rays lose in-scattering (visible
// fraction below 0.95 somewhere, never outside [0, 1] or NaN), and 32 and 128 samples estimate the
// same integral (mean visible fraction within 0.01 of each other).
TEST_F(ScatteringTest, AnOccluderShadowsTheMedium) {
  Renderer renderer(ctx(), medium_scene(true));
  double mean[2] = {0.0, 0.0};
  int k = 0;
  for (const char* technique : {"scatter-march-32", "scatter-march-128"}) {
    SCOPED_TRACE(technique);
    RenderResult r = renderer.render(settings(technique));
    float lowest = 1.0f;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        float v = r.scattering.at(x, y, 3);
        ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << x << ", " << y << ": " << v;
        for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(r.scattering.at(x, y, c)));
        lowest = std::min(lowest, v);
        mean[k] += v / (kWidth * kHeight);
      }
    fmt::print("{}: lowest visible fraction {:.3f}\n", technique, lowest);
    EXPECT_LT(lowest, 0.95f); // measured 0.896 (32 samples), 0.898 (128)
    ++k;
  }
  EXPECT_NEAR(mean[0], mean[1], 0.01);
  EXPECT_LT(mean[1], 0.999);
}

// Mean absolute difference of the visible fractions of two renders, and the largest.
std::pair<double, double> visible_difference(const RenderResult& a, const RenderResult& b) {
  double sum = 0.0, worst = 0.0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      double d = std::abs(double(a.scattering.at(x, y, 3)) - double(b.scattering.at(x, y, 3)));
      sum += d;
      worst = std::max(worst, d);
    }
  return {sum / (kWidth * kHeight), worst};
}

// Prefiltered scattering (four moments, six moments in each storage, CSM-32) against ray marching with 128
// samples (the better estimate of the same integral): unshadowed, lit from above, and with the
// wall's shadow under a tilted light. The camera's far plane is at 20 (the rectified map spans r up
// to the far plane: at the default 1000 the 256 texels of a row would be 3.5 units wide, wider than
// the ground's detail). Bounds: the MAE and largest difference measured on lavapipe (in the comments)
// with a margin; the largest differences are the rays through the shadow's edges, where the moments'
// reconstruction is least sure and ray marching has its noise.
TEST_F(ScatteringTest, PrefilteredAgreesWithRayMarching) {
  struct Bound {
    const char* technique;
    double mae[2], worst[2]; // unshadowed, wall
  };
  // §5.3.1's adaptive β (parameter z = 2).
  const Bound adaptive[] = {
      {"scatter-msm4-64", {0.02, 0.03}, {0.05, 0.15}},    // measured 0.0137 / 0.022, 0.034 / 0.093
      {"scatter-msm6-64", {0.025, 0.03}, {0.06, 0.1}},    // 0.0165 / 0.0202, 0.041 / 0.068
      {"scatter-msm6-96", {0.013, 0.018}, {0.03, 0.09}},  // 0.0085 / 0.0121, 0.019 / 0.058
      {"scatter-msm6-192", {0.01, 0.015}, {0.03, 0.09}},  // 0.0068 / 0.0101, 0.018 / 0.058
      {"scatter-csm-32", {0.015, 0.014}, {0.035, 0.045}}, // 0.0102 / 0.0089, 0.023 / 0.028
  };
  // The proportional β (the default, z = 0): the unshadowed medium exact up to the storage (nothing
  // is surely shadowed, so β = 1), the wall's MAE 2.9-6x lower than with the adaptive β. Bounds:
  // 1.5x the measurement, at least 0.001 for the MAE; the largest difference 1.5x + 0.005 (filtered:
  // its own measurement, below).
  const Bound proportional[] = {
      {"scatter-msm4-64", {0.001, 0.0116}, {0.005, 0.105}},   // measured 0.0000 / 0.0077, 0.0000 / 0.0667
      {"scatter-msm6-64", {0.001, 0.0041}, {0.0095, 0.073}},  // 0.0006 / 0.0027, 0.0030 / 0.0452
      {"scatter-msm6-96", {0.001, 0.0030}, {0.0052, 0.074}},  // 0.0000 / 0.0020, 0.0001 / 0.0459
      {"scatter-msm6-192", {0.001, 0.0030}, {0.0064, 0.074}}, // 0.0000 / 0.0020, 0.0009 / 0.0459
  };
  for (float beta_mode : {2.0f, 0.0f}) {
    const bool paper = beta_mode == 2.0f;
    SCOPED_TRACE(paper ? "adaptive beta" : "proportional beta");
    const std::span<const Bound> bounds =
        paper ? std::span<const Bound>(adaptive) : std::span<const Bound>(proportional);
    for (int wall : {0, 1}) {
      std::map<std::string, double> maes;
      SCOPED_TRACE(wall ? "wall" : "unshadowed");
      scene::Scene scene = wall ? medium_scene(true) : medium_scene(false, true, {0.0f, 1.0f, 0.0f});
      Renderer renderer(ctx(), scene);
      RenderResult march = renderer.render(settings("scatter-march-128"));
      for (const Bound& b : bounds) {
        SCOPED_TRACE(b.technique);
        RenderSettings s = settings(b.technique);
        if (find_rendered_technique(b.technique).has_parameter("beta")) s.parameters = {{"beta", beta_mode}};
        RenderResult prefiltered = renderer.render(s);
        for (float v : prefiltered.scattering.pixels()) ASSERT_TRUE(std::isfinite(v));
        auto [mae, worst] = visible_difference(prefiltered, march);
        fmt::print("{} ({} β) vs scatter-march-128 ({}): visible fraction MAE {:.4f}, max {:.4f}\n", b.technique,
                   paper ? "adaptive" : "proportional", wall ? "wall" : "unshadowed", mae, worst);
        EXPECT_LT(mae, b.mae[wall]);
        EXPECT_LT(worst, b.worst[wall]);
        maes[b.technique] = mae;
      }
      // Six moments in 96 bits have less error than four (measured: half the MAE in both scenes
      // with the adaptive β, a quarter on the wall with the proportional one; unshadowed, the
      // proportional β is exact with both).
      if (paper || wall) { EXPECT_LT(maes["scatter-msm6-96"], maes["scatter-msm4-64"]); }
      // Resampling with filtering (parameter x = 1, §5.2: from the blurred, mipmapped moment map):
      // adaptive β within the same bounds (measured, wall: MAE 0.0241 / 0.0133, max 0.089 / 0.073;
      // with the earlier bilinear moments 0.0230 / 0.0128, 0.092 / 0.060; unshadowed under light
      // from above, the ground's depth is one value and the filtered map equals the unfiltered one:
      // 0.0137 / 0.0085); proportional β, wall: MAE 0.0084 / 0.0020, max 0.0881 / 0.0732 (bounds
      // 1.5x + 0.005 on the largest difference: 0.137 / 0.115).
      for (const Bound& b : {bounds[0], bounds[2]}) {
        const char* technique = b.technique;
        RenderSettings filtered = settings(technique);
        filtered.parameters = {{"resampling", 1.0f}}; // filtered
        if (find_rendered_technique(technique).has_parameter("beta")) filtered.parameters["beta"] = beta_mode;
        RenderResult r = renderer.render(filtered);
        for (float v : r.scattering.pixels()) ASSERT_TRUE(std::isfinite(v));
        auto [mae, worst] = visible_difference(r, march);
        fmt::print("{} filtered ({} β) vs scatter-march-128 ({}): visible fraction MAE {:.4f}, max {:.4f}\n", technique,
                   paper ? "adaptive" : "proportional", wall ? "wall" : "unshadowed", mae, worst);
        const bool own = !paper && wall == 1, four = std::string(technique) == "scatter-msm4-64";
        EXPECT_LT(mae, own ? (four ? 0.0126 : 0.0030) : b.mae[wall]) << technique << " filtered";
        EXPECT_LT(worst, own ? (four ? 0.137 : 0.115) : b.worst[wall]) << technique << " filtered";
      }
    }
  }
}

// The two schemes of the prefix sums (RenderSettings::prefix_sums: a thread per row, JCGT's
// Appendix C) add the same terms in the same order, so every prefiltered technique's image is the
// same with either, up to float rounding where the compiler contracts differently (bound 1e-6 on
// every channel: the in-scattered radiance and the visible fraction). A 200² map: neither 64 nor 8 rows divide it, nor 8 columns (Appendix C's
// last block is partial). Not vacuous: the wall's shadow darkens part of the medium (visible
// fraction below 0.9); the rows' sums against ray marching: PrefilteredAgreesWithRayMarching.
TEST_F(ScatteringTest, PrefixSumSchemesAgree) {
  scene::Scene scene = medium_scene(true);
  Renderer renderer(ctx(), scene);
  for (const char* technique :
       {"scatter-msm4-64", "scatter-msm6-64", "scatter-msm6-96", "scatter-msm6-192", "scatter-csm-32"})
    for (float layers : {0.0f, 3.0f}) {
      SCOPED_TRACE(fmt::format("{}, beta=adaptive layers={}", technique, layers));
      RenderSettings s = settings(technique);
      s.shadow_size = 200;
      s.parameters = {{"layers", layers}};
      if (find_rendered_technique(technique).has_parameter("beta"))
        s.parameters["beta"] = 2.0f; // §5.3.1's β: its darker estimate makes the count below
      s.prefix_sums = RenderSettings::PrefixSums::rows;
      RenderResult rows = renderer.render(s);
      s.prefix_sums = RenderSettings::PrefixSums::appendix_c;
      RenderResult appendix_c = renderer.render(s);
      ASSERT_EQ(rows.scattering.pixels().size(), appendix_c.scattering.pixels().size());
      double worst = 0;
      for (size_t i = 0; i < rows.scattering.pixels().size(); ++i) {
        ASSERT_TRUE(std::isfinite(rows.scattering.pixels()[i]));
        worst = std::max(worst, double(std::abs(rows.scattering.pixels()[i] - appendix_c.scattering.pixels()[i])));
      }
      size_t shadowed = 0;
      for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) shadowed += rows.scattering.at(x, y, 3) < 0.9f;
      fmt::print("{} K={}: rows vs Appendix C, largest difference {:.3g}\n", technique, layers, worst);
      EXPECT_LE(worst, 1e-6);   // measured on lavapipe: 0, every technique and K
      EXPECT_GT(shadowed, 10u); // measured 14-18 (CSM) and more (the moments)
    }
}

// Without a medium the scattering pass only tone maps: the image is PCF's up to the 16-bit float
// radiance in between (at most one 8-bit step, 1/255 in sRGB), and nothing is scattered.
TEST_F(ScatteringTest, WithoutAMediumTheImageIsPcfs) {
  Renderer renderer(ctx(), medium_scene(true, false));
  RenderResult pcf = renderer.render(settings("pcf")), march = renderer.render(settings("scatter-march-32"));
  ASSERT_EQ(pcf.color.pixel_count(), march.color.pixel_count());
  for (size_t i = 0; i < pcf.color.pixels().size(); ++i)
    ASSERT_NEAR(image::linear_to_srgb(march.color.pixels()[i]), image::linear_to_srgb(pcf.color.pixels()[i]),
                1.01f / 255.0f)
        << i;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) ASSERT_EQ(march.scattering.at(x, y, 0), 0.0f);
  EXPECT_EQ(march.shadow.pixels().size(), pcf.shadow.pixels().size());
  for (size_t i = 0; i < pcf.shadow.pixels().size(); ++i) ASSERT_EQ(march.shadow.pixels()[i], pcf.shadow.pixels()[i]);
}

} // namespace
} // namespace msm::render
