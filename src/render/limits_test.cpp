// The limits shared by msm render and msm reference (msm/util/limits.h): what works today stays
// within them, absurd input is refused with the value and the limit named, and the renderer and the
// ray tracer refuse the same scene the same way. No device needed: the estimates are arithmetic.
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/techniques.h"
#include "msm/util/limits.h"
#include "msm/util/progress.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace msm {
namespace {

render::RenderSettings heaviest_working_render() {
  render::RenderSettings s; // 1280x720, 4x MSAA, mipmaps: the defaults of msm render
  s.technique = "msm6-192";
  s.shadow_size = 8192;
  return s;
}

std::string limit_message(auto&& f) {
  try {
    f();
  } catch (const limits::LimitError& e) { return e.what(); }
  return "";
}

TEST(Limits, TheHeaviestRenderTriedStaysWithinTheDefaults) {
  // `msm render --scene fence -t msm6-192 --shadow-size 8192` peaks at 4.9 GB on lavapipe (device
  // memory is host memory there): the estimate must be of that order (within 25%)
  // and within the limit, or the limit refuses what works.
  const std::uint64_t bytes = render::estimated_bytes(heaviest_working_render(), 410, 1);
  EXPECT_GT(double(bytes), 0.75 * 4.9e9);
  EXPECT_LT(double(bytes), 1.25 * 4.9e9);
  EXPECT_LT(bytes, limits::kMaxBytes);
  EXPECT_NO_THROW(render::check_limits(heaviest_working_render(), 410, 1));
}

TEST(Limits, ShadowMemoryGrowsWithTexelsLightsAndColourChannels) {
  render::RenderSettings s = heaviest_working_render();
  s.width = s.height = 1; // the shadow maps alone
  const double base = double(render::estimated_bytes(s, 0, 1));
  EXPECT_NEAR(double(render::estimated_bytes(s, 0, 4)) / base, 4.0, 1e-6);
  s.shadow_size = 4096;
  EXPECT_NEAR(base / double(render::estimated_bytes(s, 0, 1)), 4.0, 1e-6);
  s.shadow_size = 8192;
  s.coloured_translucency = true;
  EXPECT_GT(double(render::estimated_bytes(s, 0, 1)), 2.0 * base); // three moment maps, one depth
}

// Prefiltered scattering: every light has its own rectified map and prefix sums, shadow
// size² texels of msm_technique_scatter_map_bytes each, the prefix sums once per transmittance
// layer (default 1; parameter w); ray marching has neither (the techniques store no moment maps,
// so the rest of the estimate is the same).
TEST(Limits, RectifiedMapsAreCountedPerLight) {
  render::RenderSettings s;
  s.shadow_size = 2048;
  s.technique = "scatter-march-128";
  const std::uint64_t march[3] = {0, render::estimated_bytes(s, 0, 1), render::estimated_bytes(s, 0, 2)};
  for (const char* name :
       {"scatter-msm4-64", "scatter-msm6-64", "scatter-msm6-96", "scatter-msm6-192", "scatter-csm-32"}) {
    SCOPED_TRACE(name);
    s.technique = name;
    const glm::ivec2 bytes = msm_technique_scatter_map_bytes(render::find_rendered_technique(name).id);
    EXPECT_EQ(render::transmittance_layers(s), 1);
    const std::uint64_t per_light = std::uint64_t(2048) * 2048 * std::uint64_t(bytes.x + bytes.y);
    EXPECT_EQ(render::estimated_bytes(s, 0, 1) - march[1], per_light);
    EXPECT_EQ(render::estimated_bytes(s, 0, 2) - march[2], 2 * per_light);
    s.lights.resize(3); // the frame's lights instead of the scene's
    EXPECT_EQ(render::estimated_bytes(s, 0, 1) - march[1], 3 * per_light + (march[2] - march[1]) * 2);
    s.lights.clear();
    s.parameters = {{"layers", 4.0f}}; // four transmittance layers: four prefix sums
    EXPECT_EQ(render::transmittance_layers(s), 4);
    EXPECT_EQ(render::estimated_bytes(s, 0, 1) - march[1], std::uint64_t(2048) * 2048 * (bytes.x + 4 * bytes.y));
    s.reset_parameters();
  }
}

TEST(Limits, RenderAndReferenceRefuseTheSameScene) {
  const std::uint64_t triangles = 160'000'000;
  reference::Settings ref;
  const std::string a = limit_message([&] { reference::check_limits(ref, triangles); });
  const std::string b = limit_message([&] { render::check_limits(render::RenderSettings{}, triangles, 1); });
  EXPECT_EQ(a, "the scene has 160,000,000 triangles; the limit is 32,000,000 (MSM_MAX_TRIANGLES raises it)");
  EXPECT_EQ(a, b);
  EXPECT_NO_THROW(reference::check_limits(ref, limits::kMaxTriangles / 4));
}

TEST(Limits, HugeReferencesAreRefusedBeforeAllocation) {
  reference::Settings s;
  s.width = s.height = 16384;
  s.effect = reference::Effect::translucent; // four images, one of them RGB
  const std::string m = limit_message([&] { reference::check_limits(s, 410); });
  EXPECT_NE(m.find("a 16384x16384 translucent reference of 410 triangles needs about 13.0 GiB; the limit is 12.0 GiB"),
            std::string::npos)
      << m;
  s.effect = reference::Effect::hard; // 28 B per pixel measured at 4096², 40 B estimated: allowed
  EXPECT_NO_THROW(reference::check_limits(s, 410));
  EXPECT_GT(reference::estimated_bytes(s, 410), std::uint64_t(28) * 16384 * 16384);
}

TEST(Limits, TheEnvironmentOverridesEachLimit) {
  ::setenv("MSM_MAX_TRIANGLES", "1000", 1);
  ::setenv("MSM_MAX_MEMORY_MB", "1", 1);
  EXPECT_EQ(limits::max_triangles(), 1000u);
  EXPECT_EQ(limits::max_bytes(), 1u << 20);
  EXPECT_NE(limit_message([] { limits::check_triangles(1001); }), "");
  EXPECT_EQ(limit_message([] { limits::check_triangles(1000); }), "");
  // Not a positive whole number: refused, naming the variable (not the default in silence, not a
  // limit of zero, and "-5" not 2^64 - 5), as is a value whose bytes overflow.
  for (const char* bad : {"lots", "0", "-5", " 7", "7 ", "+7", "1e3", "18446744073709551616"}) {
    ::setenv("MSM_MAX_TRIANGLES", bad, 1);
    EXPECT_EQ(limit_message([] { limits::max_triangles(); }).find("MSM_MAX_TRIANGLES=" + std::string(bad) + ": "), 0u)
        << bad;
    EXPECT_NE(limit_message([] { limits::check_environment(); }), "") << bad;
  }
  ::unsetenv("MSM_MAX_TRIANGLES");
  ::setenv("MSM_MAX_MEMORY_MB", "17592186044416", 1); // 2^44 MiB = 2^64 bytes
  EXPECT_NE(limit_message([] { limits::max_bytes(); }).find("expected a whole number from 1 to 17592186044415"),
            std::string::npos);
  ::setenv("MSM_MAX_MEMORY_MB", "17592186044415", 1);
  EXPECT_EQ(limits::max_bytes(), 17592186044415ull << 20);
  ::unsetenv("MSM_MAX_MEMORY_MB");
  ::setenv("MSM_IMPORT_TIMEOUT_S", "-5", 1);
  EXPECT_NE(limit_message([] { limits::check_environment(); }).find("MSM_IMPORT_TIMEOUT_S=-5"), std::string::npos);
  ::unsetenv("MSM_IMPORT_TIMEOUT_S");
  EXPECT_EQ(limit_message([] { limits::check_environment(); }), "");
}

// Progress lines for a log: nothing from a short run; from a long one a line per tenth once it has
// run two seconds, each tenth once, and the last line at the end.
TEST(ProgressLines, ShortRunsAreQuietLongRunsGetATenthPerLine) {
  util::ProgressLines quick("msm reference: ");
  for (std::size_t done = 1; done <= 100; ++done) EXPECT_FALSE(quick.next(done, 100, 0.01 * double(done)));

  util::ProgressLines slow("msm reference: ");
  std::vector<std::string> lines;
  for (std::size_t done = 1; done <= 100; ++done)
    for (int repeat = 0; repeat < 2; ++repeat) // a report repeated prints nothing more
      if (auto line = slow.next(done, 100, 0.1 * double(done))) lines.push_back(*line);
  ASSERT_EQ(lines.size(), 9u); // 20%, 30%, ..., 100%: the first tenth came before 2 s
  EXPECT_EQ(lines.front(), "msm reference:  20% (20 of 100), 2.0 s, 8.0 s left");
  EXPECT_EQ(lines.back(), "msm reference: 100% (100 of 100), 10.0 s, 0.0 s left");

  // Reports coarser than a tenth (a few rows of a tall image at a time): one line per report.
  util::ProgressLines coarse("x ");
  EXPECT_FALSE(coarse.next(0, 3, 5.0));
  EXPECT_EQ(coarse.next(1, 3, 6.0).value_or(""), "x  33% (1 of 3), 6.0 s, 12.0 s left");
  EXPECT_TRUE(coarse.next(3, 3, 9.0));
  EXPECT_FALSE(coarse.next(3, 3, 9.0));
}

} // namespace
} // namespace msm
