// Cascaded shadow maps' fit (scene::fit_cascades): the practical split scheme, every visible point
// inside each cascade that shades it, weights that sum to 1 across the blend bands, finer texels
// than one map where one map is too coarse, and the stabilisation (texel grid fixed in the world
// as the camera moves).
#include <cmath>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "msm/cascade.h"
#include "msm/scene/scene.h"

using namespace msm::scene;

namespace {

Scene box_on_ground() { return load_scene_file(std::string(MSM_SCENES_DIR) + "/box_on_ground.json"); }

// The world point's map coordinates in texels (x, y) and depth of a cascade.
glm::dvec3 map_texel(const LightFrame& f, glm::dvec3 p, int shadow_size) {
  const glm::dvec4 q = glm::dmat4(f.view_projection) * glm::dvec4(p, 1.0);
  return {(q.x * 0.5 + 0.5) * shadow_size, (q.y * 0.5 + 0.5) * shadow_size, q.z};
}

double view_depth(const Camera& camera, glm::dvec3 p) { return -(glm::dmat4(camera.view()) * glm::dvec4(p, 1.0)).z; }

} // namespace

TEST(Cascades, PracticalSplitScheme) {
  const std::vector<double> uniform = cascade_splits(1.0, 101.0, 4, 0.0);
  const std::vector<double> log = cascade_splits(1.0, 10001.0, 4, 1.0);
  ASSERT_EQ(uniform.size(), 5u);
  for (int i = 0; i <= 4; ++i) {
    EXPECT_NEAR(uniform[std::size_t(i)], 1.0 + 25.0 * i, 1e-9);
    EXPECT_NEAR(log[std::size_t(i)], std::pow(10001.0, i / 4.0), 1e-6 * log[std::size_t(i)]);
  }
  const std::vector<double> blend = cascade_splits(0.5, 300.0, 8, 0.75);
  for (std::size_t i = 1; i < blend.size(); ++i) EXPECT_GT(blend[i], blend[i - 1]);
  EXPECT_EQ(blend.front(), 0.5);
  EXPECT_EQ(blend.back(), 300.0);
}

// Every point of the ground and the box the camera sees (a grid over the visible ground, the box's
// corners) lies inside the map of each cascade whose weight is above 0 there, at depth in [0, 1];
// the weights at its view depth sum to 1; one cascade takes it whole outside the bands.
TEST(Cascades, EveryVisiblePointIsInTheCascadesThatShadeIt) {
  const Scene s = box_on_ground();
  const int size = 1024;
  for (int count : {2, 4, 8}) {
    SCOPED_TRACE(count);
    const std::vector<Cascade> cascades = fit_cascades(s, s.light(), size, {.count = count});
    ASSERT_EQ(cascades.size(), std::size_t(count));
    const glm::dvec2 range = visible_depth_range(s);
    const glm::mat4 camera = s.camera_view_projection(kFitMaxAspect);
    int checked = 0, in_bands = 0;
    for (double z = -250.0; z <= 10.0; z += 0.25)
      for (double x = -250.0; x <= 250.0; x += x > -20.0 && x < 20.0 ? 0.25 : 2.0) {
        const glm::dvec3 p(x, 0.0, z);
        const glm::vec4 c = camera * glm::vec4(glm::vec3(p), 1.0f);
        if (!(c.w > 0.0f && std::abs(c.x) <= c.w && std::abs(c.y) <= c.w && c.z >= 0.0f && c.z <= c.w)) continue;
        const double depth = view_depth(s.camera, p);
        ASSERT_GE(depth, range.x * (1 - 1e-6));
        ASSERT_LE(depth, range.y * (1 + 1e-6));
        double sum = 0.0;
        int shading = 0;
        for (const Cascade& k : cascades) {
          const glm::vec4 packed(float(k.fade_in.x), float(k.fade_in.y), float(k.fade_out.x), float(k.fade_out.y));
          const float w = msm::msm_cascade_weight(packed, float(depth));
          sum += w;
          if (w <= 0.0f) continue;
          ++shading;
          const glm::dvec3 t = map_texel(k.frame, p, size);
          ASSERT_TRUE(t.x >= 0.0 && t.x <= size && t.y >= 0.0 && t.y <= size) << x << ", " << z << ": " << t.x;
          ASSERT_TRUE(t.z >= 0.0 && t.z <= 1.0) << t.z;
        }
        EXPECT_NEAR(sum, 1.0, 1e-5);
        ASSERT_GE(shading, 1);
        ASSERT_LE(shading, 2);
        in_bands += shading == 2;
        ++checked;
      }
    EXPECT_GT(checked, 10000);
    EXPECT_GT(in_bands, 100);
  }
}

// On the box on the 500 m ground one map's texel spans many pixels at the nearest surface (the
// warning's case); four cascades' texels there do not (no warning), and each cascade's texels are
// coarser than the one's before it.
TEST(Cascades, NearCascadesHaveFinerTexels) {
  const Scene s = box_on_ground();
  const TexelCoverage one = shadow_texel_coverage(s, 1280, 720, 1024);
  EXPECT_GT(one.pixels_per_texel, kMaxPixelsPerTexel);
  const std::optional<std::string> warning = shadow_framing_warning(s, 1280, 720, 1024);
  ASSERT_TRUE(warning.has_value());
  EXPECT_NE(warning->find("--cascades 4"), std::string::npos) << *warning;
  const CascadeOptions four{.count = 4};
  const TexelCoverage cascaded = shadow_texel_coverage(s, 1280, 720, 1024, four);
  EXPECT_LT(cascaded.pixels_per_texel, kMaxPixelsPerTexel);
  EXPECT_FALSE(shadow_framing_warning(s, 1280, 720, 1024, four).has_value());
  // Looking along the ground from 5 cm above it the nearest surface is too close for 4 cascades:
  // the warning stays, and names more.
  Scene low = s;
  low.camera.position.y = 0.05f;
  low.camera.target = {0.0f, 0.05f, -10.0f};
  const std::optional<std::string> still = shadow_framing_warning(low, 1280, 720, 1024, four);
  ASSERT_TRUE(still.has_value());
  EXPECT_NE(still->find("--cascades 8"), std::string::npos) << *still;
  const std::vector<Cascade> cascades = fit_cascades(s, s.light(), 1024, four);
  for (std::size_t i = 1; i < cascades.size(); ++i)
    EXPECT_GT(cascades[i].frame.texel(1024).x, cascades[i - 1].frame.texel(1024).x);
}

// Stabilisation: as the camera pans and moves by fractions of a texel, each cascade's texel size
// stays the same and a fixed world point stays at the same place within its texel (the grid moves
// by whole texels); without it the grid slides.
TEST(Cascades, StabilisedGridsMoveByWholeTexels) {
  const Scene s = box_on_ground();
  const int size = 1024;
  const glm::dvec3 point(0.3, 0.0, -0.7);
  for (bool stabilize : {true, false}) {
    SCOPED_TRACE(stabilize);
    const CascadeOptions options{.count = 4, .stabilize = stabilize};
    const std::vector<Cascade> first = fit_cascades(s, s.light(), size, options);
    double largest_slide = 0.0;
    for (int frame = 1; frame <= 8; ++frame) {
      Scene moved = s;
      const float turn = glm::radians(0.05f * float(frame));
      const glm::vec3 d = s.camera.target - s.camera.position;
      moved.camera.target = s.camera.position + glm::vec3(std::cos(turn) * d.x - std::sin(turn) * d.z, d.y,
                                                          std::sin(turn) * d.x + std::cos(turn) * d.z);
      moved.camera.position += glm::vec3(0.013f * float(frame), 0.0f, 0.0f);
      moved.camera.target += glm::vec3(0.013f * float(frame), 0.0f, 0.0f);
      const std::vector<Cascade> now = fit_cascades(moved, moved.light(), size, options);
      for (std::size_t k = 0; k < now.size(); ++k) {
        const glm::dvec3 a = map_texel(first[k].frame, point, size), b = map_texel(now[k].frame, point, size);
        const double slide =
            std::max(std::abs(std::remainder(a.x - b.x, 1.0)), std::abs(std::remainder(a.y - b.y, 1.0)));
        largest_slide = std::max(largest_slide, slide);
        if (stabilize) { EXPECT_NEAR(now[k].frame.extent.x, first[k].frame.extent.x, 1e-9 * first[k].frame.extent.x); }
      }
    }
    if (stabilize) {
      EXPECT_LT(largest_slide, 1e-3);
    } else {
      EXPECT_GT(largest_slide, 0.05);
    }
  }
}

// A given depth range (the renderer's depth-buffer bounds) is what the splits divide, in place of
// the scene's estimate: the first cascade's far end and the last's near band at the practical
// scheme's splits of it; a range beyond the camera's planes is clamped to them and an empty one
// still gives increasing slices; a tighter range gives the near cascade finer texels.
TEST(Cascades, SplitTheGivenDepthRange) {
  const Scene s = box_on_ground();
  const int size = 1024;
  const CascadeOptions scene_estimate{.count = 4};
  CascadeOptions given = scene_estimate;
  given.depth_range = glm::dvec2(3.0, 40.0);
  const std::vector<double> splits = cascade_splits(3.0, 40.0, 4, given.lambda);
  const std::vector<Cascade> fitted = fit_cascades(s, s.light(), size, given);
  ASSERT_EQ(fitted.size(), 4u);
  for (std::size_t i = 0; i + 1 < fitted.size(); ++i) EXPECT_EQ(fitted[i].fade_out.y, splits[i + 1]) << i;
  EXPECT_EQ(fitted[3].fade_in.y, splits[3]);
  const std::vector<Cascade> estimated = fit_cascades(s, s.light(), size, scene_estimate);
  EXPECT_NE(estimated[0].fade_out.y, fitted[0].fade_out.y);
  EXPECT_LT(fitted[0].frame.texel(size).x, estimated[0].frame.texel(size).x);

  given.depth_range = glm::dvec2(0.001, 1e6); // beyond near 0.1 and far 1000
  const std::vector<double> clamped = cascade_splits(s.camera.near, s.camera.far, 4, given.lambda);
  const std::vector<Cascade> wide = fit_cascades(s, s.light(), size, given);
  EXPECT_NEAR(wide[0].fade_out.y, clamped[1], 1e-9 * clamped[1]);
  EXPECT_NEAR(wide[3].fade_in.y, clamped[3], 1e-9 * clamped[3]);

  given.depth_range = glm::dvec2(7.0, 7.0); // one depth: a flat wall facing the camera
  const std::vector<Cascade> flat = fit_cascades(s, s.light(), size, given);
  for (std::size_t i = 1; i + 1 < flat.size(); ++i) EXPECT_GT(flat[i].fade_out.y, flat[i - 1].fade_out.y);
  for (const Cascade& k : flat) EXPECT_TRUE(std::isfinite(k.frame.texel(size).x));
}
