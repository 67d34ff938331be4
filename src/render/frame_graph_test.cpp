// The frame graph: recipes are ordered and checked from their passes' declarations (no device
// needed), and frames with several lights render each light's shadow from its own layer.
#include "frame_config.h"
#include "frame_graph.h"
#include "passes/pass.h"
#include "recipes.h"

#include "msm/image/metrics.h"
#include "msm/render/renderer.h"
#include "msm/techniques.h"
#include "msm/test/render_settings.h"
#include "msm/test/vulkan_test.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace msm::render {
namespace {

FrameConfig config_of(std::string_view technique, bool translucent = false, bool coloured = false) {
  FrameConfig c;
  c.technique = &find_rendered_technique(technique);
  c.width = 64;
  c.height = 36;
  c.shadow_size = 64;
  c.msaa = 4;
  c.taps = 9;
  c.mip_levels = 7;
  c.translucent = translucent;
  c.coloured = coloured;
  return c;
}

std::vector<std::string> names_in_order(const std::vector<std::unique_ptr<Pass>>& passes) {
  std::vector<std::string> names;
  for (size_t i : order_passes(passes, {}, frame_outputs())) names.emplace_back(passes[i]->name());
  return names;
}

TEST(FrameGraph, RecipesListTheirPassesInOrder) {
  using V = std::vector<std::string>;
  // pcf, pcss and the soft techniques are shaded deferred (a surfaces pass first).
  EXPECT_EQ(technique_passes(find_rendered_technique("pcf")), (V{"shadow_depth", "surfaces", "shading"}));
  EXPECT_EQ(technique_passes(find_rendered_technique("plain")), (V{"shadow_depth", "shading"}));
  EXPECT_EQ(technique_passes(find_rendered_technique("msm-hamburger-64")),
            (V{"shadow_depth", "moment_resolve", "blur", "mipmaps", "shading"}));
  EXPECT_EQ(technique_passes(find_rendered_technique("msm-hamburger-64"), true),
            (V{"shadow_depth", "moment_resolve", "translucent", "blur", "mipmaps", "shading"}));
  EXPECT_EQ(technique_passes(find_rendered_technique("msm-hamburger-64"), true, true),
            (V{"shadow_depth", "moment_resolve", "channel_copy", "translucent", "blur", "mipmaps", "translucent",
               "blur", "mipmaps", "translucent", "blur", "mipmaps", "shading"}));
  EXPECT_EQ(technique_passes(find_rendered_technique("msm-nl64")), (V{"shadow_depth", "one_pass_filter", "shading"}));
  EXPECT_EQ(technique_passes(find_rendered_technique("mssm6")),
            (V{"shadow_depth", "moment_resolve", "sat", "surfaces", "shading"}));
}

// Prefiltered scattering with filtered resampling (JCGT §5.2, FrameConfig::filtered_resampling):
// the frame adds the blurred, mipmapped moment map that rectify reads; without it, rectify reads
// the depth map.
TEST(FrameGraph, FilteredResamplingAddsTheMomentMapPasses) {
  using V = std::vector<std::string>;
  for (std::string_view technique : {"scatter-msm4-64", "scatter-msm6-96", "scatter-csm-32"}) {
    FrameConfig c = config_of(technique);
    c.mip_levels = 1;
    auto names = [&] {
      std::vector<std::unique_ptr<Pass>> passes = recipe(c);
      std::vector<std::string> n;
      for (size_t i : order_passes(passes, {}, frame_outputs(c))) n.emplace_back(passes[i]->name());
      return n;
    };
    EXPECT_EQ(names(), (V{"shadow_depth", "shading", "rectify", "prefix_sums", "scattering"})) << technique;
    c.filtered_resampling = true;
    c.resampling_mips = 7;
    EXPECT_EQ(names(), (V{"shadow_depth", "shading", "moment_resolve", "blur", "mipmaps", "rectify", "prefix_sums",
                          "scattering"}))
        << technique;
    EXPECT_EQ(c.resampling_moments().technique->id, msm::MSM_TECH_HAMBURGER_128_UNIT);
    EXPECT_EQ(c.resampling_moments().mip_levels, 7u);
    c.taps = 1; // --filter 1: no blur
    c.resampling_mips = 1;
    EXPECT_EQ(names(), (V{"shadow_depth", "shading", "moment_resolve", "rectify", "prefix_sums", "scattering"}))
        << technique;
    // App. D.5's mips of the prefix sums: blitted after the sums, before the scattering reads them.
    c.prefix_sum_mips = 10;
    EXPECT_EQ(names(), (V{"shadow_depth", "shading", "moment_resolve", "rectify", "prefix_sums", "prefix_sum_mips",
                          "scattering"}))
        << technique;
  }
}

// The order comes from the declarations, not from the list: a shuffled recipe runs in the same
// order (the in-place modifiers of one image keep their recipe order: blur before mipmaps).
TEST(FrameGraph, OrdersShuffledRecipesByTheirDeclarations) {
  for (std::string_view technique : {"msm-hamburger-64", "vsm-32", "mssm4", "pcss", "msm-nl32"}) {
    FrameConfig c = config_of(technique);
    c.one_pass = technique == "msm-nl32";
    std::vector<std::string> expected = names_in_order(recipe(c));
    std::mt19937 rng(7);
    for (int trial = 0; trial < 10; ++trial) {
      std::vector<std::unique_ptr<Pass>> passes = recipe(c);
      std::shuffle(passes.begin(), passes.end(), rng);
      // The one order the graph cannot know: blur and mipmaps both modify the moments in place.
      auto blur = std::find_if(passes.begin(), passes.end(), [](auto& p) { return p->name() == "blur"; });
      auto mips = std::find_if(passes.begin(), passes.end(), [](auto& p) { return p->name() == "mipmaps"; });
      if (blur != passes.end() && mips != passes.end() && mips < blur) std::iter_swap(blur, mips);
      EXPECT_EQ(names_in_order(passes), expected) << technique << ", trial " << trial;
    }
  }
}

// A pass whose input no pass produces is refused, naming the pass and the image.
TEST(FrameGraph, RefusesAnInputWithoutProducer) {
  FrameConfig c = config_of("msm-hamburger-64");
  std::vector<std::unique_ptr<Pass>> passes;
  passes.push_back(std::make_unique<ShadowDepthPass>(c));
  passes.push_back(std::make_unique<BlurPass>(c, 0)); // no moment_resolve creates the moments
  passes.push_back(std::make_unique<ShadingPass>(c));
  try {
    order_passes(passes, {}, frame_outputs());
    FAIL() << "accepted a frame without moment_resolve";
  } catch (const RenderError& e) {
    EXPECT_STREQ(e.what(), "pass 'blur' modifies 'moments0', which no pass of the frame creates");
  }
  // Two creators of one image, and an output nobody creates.
  passes.clear();
  passes.push_back(std::make_unique<ShadowDepthPass>(c));
  passes.push_back(std::make_unique<ShadowDepthPass>(c));
  passes.push_back(std::make_unique<ShadingPass>(c));
  EXPECT_THROW(order_passes(passes, {}, frame_outputs()), RenderError);
  passes.pop_back();
  EXPECT_THROW(order_passes({}, {}, frame_outputs()), RenderError);
}

class MultiLightTest : public vk::test::VulkanTest {};

RenderSettings small(std::string technique) { return test::render_settings(std::move(technique), 160, 90, 256); }

// Every light's shadow comes from its own layer: with light B switched off (no irradiance), a frame
// of {A, B} equals the frame of A alone, and with A off it equals B alone (a mix-up of layers or
// light uniforms shows as B's shadows under A's light). Two copies of A at half its irradiance
// equal A. Per-light pass times are reported.
// GCC 12 warns that copying a light reads its disengaged std::optional x_axis uninitialized (GCC bug
// 80635, a false positive of std::optional's trivial copy); nothing reads it.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
TEST_F(MultiLightTest, EachLightCastsItsOwnShadow) {
  scene::Scene scene = scene::builtin_scene("fence");
  // NOLINTNEXTLINE(performance-unnecessary-copy-initialization): a value, not a view into the scene
  const scene::DirectionalLight a = scene.light();
  scene::DirectionalLight b = a;
  b.towards_light = glm::normalize(glm::vec3(-0.6f, 0.7f, -0.4f));
  scene::DirectionalLight a_off = a, b_off = b;
  a_off.irradiance = b_off.irradiance = glm::vec3(0.0f);
  scene::DirectionalLight half = a;
  half.irradiance *= 0.5f;
  Renderer renderer(ctx(), scene);
  for (std::string technique : {"pcf", "msm-hamburger-64", "mssm4", "msm-nl32", "evsm4-64"}) {
    SCOPED_TRACE(technique);
    RenderSettings s = small(technique);
    auto render_with = [&](std::vector<scene::DirectionalLight> lights) {
      s.lights = std::move(lights);
      return renderer.render(s);
    };
    RenderResult only_a = render_with({a}), only_b = render_with({b});
    RenderResult a_then_off = render_with({a, b_off}), off_then_b = render_with({a_off, b});
    RenderResult halves = render_with({half, half});
    image::Image mask = only_a.shadow.channel("background");
    auto mae = [&](const RenderResult& x, const RenderResult& y, const char* channel) {
      return image::compute_metrics(x.shadow.channel(channel), y.shadow.channel(channel), {.mask = &mask}).mae;
    };
    EXPECT_LT(mae(only_a, only_b, "visibility"), 1.0) << "sanity";
    EXPECT_GT(image::compute_metrics(only_a.shadow.channel("visibility"), only_b.shadow.channel("visibility"),
                                     {.mask = &mask})
                  .mae,
              0.02)
        << "the two lights must cast different shadows";
    EXPECT_LT(mae(a_then_off, only_a, "visibility"), 1e-6);
    EXPECT_LT(mae(off_then_b, only_b, "visibility"), 1e-6);
    EXPECT_LT(mae(halves, only_a, "visibility"), 1e-6);
    EXPECT_LT(image::compute_metrics(a_then_off.color, only_a.color).max_error, 1e-6);
    EXPECT_LT(image::compute_metrics(off_then_b.color, only_b.color).max_error, 1e-6);
    // Radiance of two half lights: the same up to rounding of the 8-bit sRGB output.
    EXPECT_LT(image::compute_metrics(halves.color, only_a.color).max_error, 0.01);
    ASSERT_FALSE(halves.light_passes.empty());
    EXPECT_TRUE(std::any_of(halves.light_passes.begin(), halves.light_passes.end(),
                            [](const LightPassTime& t) { return t.pass == "shadow_depth" && t.light == 1; }));
    EXPECT_TRUE(only_a.light_passes.empty());
  }
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

} // namespace
} // namespace msm::render
