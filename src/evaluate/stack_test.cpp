// Depth-peeled stacks (msm::reference::trace_layers) and their fragments (stack.h) on scenes whose
// surfaces are known: parallel planes, a box.
#include "msm/evaluate/stack.h"

#include "msm/evaluate/evaluate.h"
#include "msm/reference/layers.h"
#include "msm/scene/scene.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <string>

namespace msm::evaluate {
namespace {

// k horizontal planes of the same size at heights 0, 1, .., k - 1, lit from straight above (the
// fitted light frustum then holds exactly the planes).
scene::Scene planes(int k) {
  std::string objects;
  for (int i = 0; i < k; ++i)
    objects += fmt::format(R"({}{{ "name": "plane{}", "primitive": {{ "type": "plane", "size": [4, 4] }},
                              "transform": {{ "translate": [0, {}, 0] }} }})",
                           i ? "," : "", i, i);
  const std::string json = fmt::format(R"({{ "msm_scene": 1, "light": {{ "towards_light": [0, 1, 0] }},
                                          "objects": [{}] }})",
                                       objects);
  return scene::load_scene_json(json, ".", "planes");
}

StackSettings small(int size = 32) {
  StackSettings s;
  s.size = size;
  s.grid = 257;
  return s;
}

TEST(Stack, ParallelPlanesGiveExactlyKFragmentsPerTexel) {
  for (int k = 1; k <= 4; ++k) {
    const scene::Scene scene = planes(k);
    reference::LayerSettings layer_settings;
    layer_settings.size = 32;
    const reference::ShadowLayers layers = reference::trace_layers(scene, layer_settings);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const auto hits = layers.texel(x, y);
        ASSERT_EQ(int(hits.size()), k) << "texel " << x << ", " << y;
        for (int i = 0; i < k; ++i) {
          EXPECT_TRUE(hits[i].faces_light);
          if (i > 0) { EXPECT_GT(hits[i].depth, hits[i - 1].depth); }
          // The planes face the light squarely: no slope.
          EXPECT_NEAR(hits[i].depth_gradient.x, 0.0, 1e-9);
          EXPECT_NEAR(hits[i].depth_gradient.y, 0.0, 1e-9);
        }
        if (k > 1) {
          // Equally spaced planes, the first at depth 0 and the last at depth 1 (fitted frustum).
          EXPECT_NEAR(hits[0].depth, 0.0, 1e-4);
          EXPECT_NEAR(hits[k - 1].depth, 1.0, 1e-4);
        }
      }
    const Stack stack = make_stack("planes", layers, small());
    EXPECT_EQ(stack.stats.fragments, 32 * 32 * k);
    EXPECT_EQ(stack.stats.counted, 32 * 32 * k);
    // The top plane is lit, every plane below it fully shadowed, with PCF as the reference.
    for (const Fragment& f : stack.fragments) EXPECT_EQ(f.pcf, f.layer == 0 ? 0.0 : 1.0);
    EXPECT_EQ(stack.stats.lit, 32 * 32);
  }
}

TEST(Stack, FarSidesOfClosedMeshesAreInTheStackButReceiveNoLight) {
  const scene::Scene scene = scene::load_scene_json(
      R"({ "msm_scene": 1, "light": { "towards_light": [0, 1, 0] },
           "objects": [ { "primitive": { "type": "box", "size": [2, 1, 2] } } ] })",
      ".", "box");
  const Stack stack = build_stack("box", scene, small(16));
  EXPECT_EQ(stack.stats.fragments, 2 * 16 * 16); // top and bottom face
  EXPECT_EQ(stack.stats.counted, 16 * 16);       // the bottom faces away from the light
  for (const Fragment& f : stack.fragments) EXPECT_EQ(f.counted, f.layer == 0);
}

TEST(Stack, PcfAgainstItselfIsExactlyZero) {
  const Stack stack = build_stack("fence", scene::builtin_scene("fence"), small(48));
  Candidate pcf;
  pcf.technique = Technique::pcf;
  pcf.name = "pcf";
  const SceneSums sums = evaluate(stack, pcf, nullptr);
  EXPECT_EQ(sums.fragments, stack.stats.counted);
  EXPECT_GT(sums.fragments, 0);
  EXPECT_EQ(sums.error_sum, 0.0);
  EXPECT_EQ(sums.max_error, 0.0);
  // And the closed form of PCF at the receiver depth is the stack's PCF.
  for (const Fragment& f : stack.fragments)
    EXPECT_NEAR(closed_form_shadow(Technique::pcf, stack.kernel(f.texel), f.receiver, stack.settings.grid), f.pcf,
                1e-12);
}

TEST(Stack, KernelsAreDistributionsOnTheGrid) {
  const Stack stack = build_stack("stair", scene::builtin_scene("stair"), small(40));
  const std::vector<double> weights = kernel_weights(9, 2.4f);
  double total = 0.0;
  for (double w : weights) total += w;
  EXPECT_NEAR(total, 1.0, 1e-15);
  for (std::size_t t = 0; t + 1 < stack.kernel_offsets.size(); ++t) {
    const auto kernel = stack.kernel(std::int32_t(t));
    if (kernel.empty()) continue;
    double sum = 0.0;
    for (std::size_t i = 0; i < kernel.size(); ++i) {
      sum += kernel[i].weight;
      EXPECT_GE(kernel[i].index, 0);
      EXPECT_LT(kernel[i].index, 257);
      if (i > 0) { EXPECT_GT(kernel[i].index, kernel[i - 1].index); }
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
  }
  // The receiver-plane bias: zf below the surface by at least two grid steps.
  for (const Fragment& f : stack.fragments) EXPECT_LE(f.cutoff, 256);
}

TEST(Stack, SerializationRoundTrips) {
  const Stack stack = build_stack("fence", scene::builtin_scene("fence"), small(24));
  const Stack copy = Stack::deserialize(stack.serialize());
  EXPECT_EQ(copy.serialize(), stack.serialize());
  EXPECT_EQ(copy.fingerprint(), stack.fingerprint());
  // The ray tracer's threads do not change a bit.
  StackSettings one_thread = small(24);
  one_thread.threads = 1;
  EXPECT_EQ(build_stack("fence", scene::builtin_scene("fence"), one_thread).fingerprint(), stack.fingerprint());
  std::vector<char> bytes = stack.serialize();
  bytes.resize(bytes.size() / 2);
  EXPECT_THROW(Stack::deserialize(bytes), std::runtime_error);
}

TEST(Stack, BadSettingsAreRejected) {
  StackSettings s = small();
  s.grid = 1;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s = small();
  s.filter_taps = 8;
  EXPECT_THROW(validate(s), std::invalid_argument);
  s = small();
  s.size = 0;
  EXPECT_THROW(validate(s), std::invalid_argument);
}

} // namespace
} // namespace msm::evaluate
