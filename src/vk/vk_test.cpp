// Tests of the msm::vk layer on the device MSM_DEVICE picks (lavapipe here), validation on.
#include "msm/shared.h"
#include "msm/test/thrown.h"
#include "msm/test/vulkan_test.h"
#include "msm/vk/vk.h"
#include "shaders/vk_bindings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace msm::vk {
namespace {

using test::VulkanTest;

// Runs `body` with an environment variable set, restoring the old value.
template <class F>
void with_env(const char* name, const char* value, F&& body) {
  const char* old = std::getenv(name);
  std::string saved = old ? old : "";
  setenv(name, value, 1);
  try {
    body();
  } catch (...) {
    old ? setenv(name, saved.c_str(), 1) : unsetenv(name);
    throw;
  }
  old ? setenv(name, saved.c_str(), 1) : unsetenv(name);
}

ContextOptions quiet_options(std::string device = "") {
  ContextOptions options = test::test_options();
  options.device = std::move(device);
  options.verbose = false;
  return options;
}

TEST(ErrorTest, CheckThrowsWithResultNameAndCallSite) {
  try {
    MSM_VK_CHECK(VK_ERROR_DEVICE_LOST);
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.result(), VK_ERROR_DEVICE_LOST);
    std::string what = e.what();
    EXPECT_NE(what.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << what;
    EXPECT_NE(what.find("vk_test.cpp"), std::string::npos) << what;
    EXPECT_EQ(what.rfind("the device was lost", 0), 0u) << what; // what a user can act on, first
  }
  EXPECT_NO_THROW(MSM_VK_CHECK(VK_SUCCESS));
  EXPECT_STREQ(result_name(VK_ERROR_OUT_OF_DEVICE_MEMORY), "VK_ERROR_OUT_OF_DEVICE_MEMORY");
  EXPECT_STREQ(result_name(VkResult(-12345)), "VkResult(-12345)");
}

TEST(ShaderRegistryTest, FindsShadersByFileNameAndStem) {
  std::span<const uint32_t> by_stem = embedded_shader("selftest");
  ASSERT_GT(by_stem.size(), 5u);
  EXPECT_EQ(by_stem[0], 0x07230203u); // SPIR-V magic
  EXPECT_EQ(embedded_shader("selftest.comp").data(), by_stem.data());
  EXPECT_NE(embedded_shader("selftest_image").data(), by_stem.data());
  std::vector<std::string> names = embedded_shader_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "selftest_image.comp"), names.end());
  // msm_vk's own (the Context's fma probe), linked through the static library's anchor.
  EXPECT_NE(std::find(names.begin(), names.end(), "fma_probe.comp"), names.end());
}

TEST(ShaderRegistryTest, UnknownNameThrowsAndListsEmbeddedShaders) {
  const std::string what = msm::test::thrown_message<std::runtime_error>([] { embedded_shader("no_such_shader"); });
  EXPECT_NE(what.find("no_such_shader"), std::string::npos) << what;
  EXPECT_NE(what.find("selftest"), std::string::npos) << what;
}

TEST(ContextTest, CreatesLavapipeDeviceWithValidation) {
  std::shared_ptr<ValidationLog> log;
  {
    std::unique_ptr<Context> ctx;
    try {
      ctx = std::make_unique<Context>(quiet_options("cpu"));
    } catch (const std::runtime_error& e) { GTEST_SKIP() << "no lavapipe here: " << e.what(); }
    ASSERT_TRUE(test::validation_active(*ctx));
    log = ctx->validation_log();
    EXPECT_EQ(ctx->info().type, VK_PHYSICAL_DEVICE_TYPE_CPU);
    EXPECT_NE(ctx->info().name.find("llvmpipe"), std::string::npos) << ctx->info().describe();
    EXPECT_GE(ctx->info().api_version, VK_API_VERSION_1_3);
    EXPECT_NE(ctx->info().describe().find(ctx->info().driver_name), std::string::npos);
    EXPECT_TRUE(ctx->features().v13.synchronization2);
    EXPECT_TRUE(ctx->features().v13.dynamicRendering);
    EXPECT_TRUE(ctx->features().v12.timelineSemaphore);
    EXPECT_NE(ctx->cmd_push_descriptor_set_with_template(), nullptr);
    EXPECT_NE(ctx->queue(), VK_NULL_HANDLE);
  }
  // Destruction included: the layer reports leaked objects at vkDestroyDevice.
  EXPECT_TRUE(test::no_validation_messages(*log));
}

TEST(ContextTest, SelectsDevicesByIndexNameAndEnvironment) {
  Context by_index(quiet_options("0"));
  EXPECT_EQ(by_index.info().index, 0u);
  std::string name = by_index.info().name;
  // Case-insensitive substring of the name.
  std::string upper = name.substr(0, 4);
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return char(std::toupper(c)); });
  EXPECT_EQ(Context(quiet_options(upper)).info().index, 0u);
  with_env("MSM_DEVICE", "0", [] { EXPECT_EQ(Context(quiet_options()).info().index, 0u); });
  // An unknown selector fails, naming what it looked for and what exists.
  with_env("MSM_DEVICE", "no-such-device", [&] {
    try {
      Context ctx(quiet_options());
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      std::string what = e.what();
      EXPECT_NE(what.find("no-such-device"), std::string::npos) << what;
      EXPECT_NE(what.find("MSM_DEVICE"), std::string::npos) << what;
      EXPECT_NE(what.find(name), std::string::npos) << what;
    }
  });
  // "gpu" gives a GPU or an error, never lavapipe.
  try {
    Context gpu(quiet_options("gpu"));
    EXPECT_TRUE(gpu.info().type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU ||
                gpu.info().type == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU);
  } catch (const std::runtime_error& e) { EXPECT_NE(std::string(e.what()).find("GPU"), std::string::npos) << e.what(); }
}

// A context whose validation messages are kept, not echoed, for tests that misuse Vulkan on
// purpose; skipped where the validation layer is not installed. The log outlives the context, so
// that what its destruction reports can be read.
class ValidationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ContextOptions options = quiet_options();
    options.echo_validation = false;
    context.emplace(options);
    if (!context->validation_enabled()) {
      ASSERT_TRUE(test::validation_active(*context));
      GTEST_SKIP() << "validation layer not installed";
    }
    log = context->validation_log();
  }

  std::optional<Context> context;
  std::shared_ptr<ValidationLog> log;
};

// The checks of the other tests can fail: a deliberate misuse is reported.
TEST_F(ValidationTest, ReportsAnOutOfRangeBufferBarrier) {
  {
    const Context& ctx = *context;
    Buffer buffer = create_buffer(ctx, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    ASSERT_EQ(log->count(), 0u) << ValidationLog::format(log->messages());
    submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
      // offset must be less than the buffer's size (VUID-VkBufferMemoryBarrier2-offset-01187).
      pipeline_barrier(cmd, buffer_barrier(buffer.handle(), VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                           VK_ACCESS_2_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                           VK_ACCESS_2_SHADER_READ_BIT, 1024, 16));
    });
    std::vector<ValidationMessage> messages = log->messages();
    ASSERT_FALSE(messages.empty());
    EXPECT_TRUE(std::any_of(messages.begin(), messages.end(), [](const ValidationMessage& m) {
      return m.severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT &&
             m.id.find("offset-01187") != std::string::npos;
    })) << ValidationLog::format(messages);
    log->clear();
  }
  context.reset();
  EXPECT_TRUE(test::no_validation_messages(*log)); // nothing else went wrong, destruction included
}

// ... and an object never destroyed is reported when the Context goes.
TEST_F(ValidationTest, ReportsObjectsAliveAtDeviceDestruction) {
  VkSamplerCreateInfo info{.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, .maxLod = 1.0f};
  VkSampler leaked = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateSampler(context->device(), &info, nullptr, &leaked));
  context.reset();
  std::vector<ValidationMessage> messages = log->messages();
  EXPECT_TRUE(std::any_of(messages.begin(), messages.end(), [](const ValidationMessage& m) {
    return m.text.find("VkSampler") != std::string::npos;
  })) << ValidationLog::format(messages);
}

class VkLayerTest : public VulkanTest {};

TEST_F(VkLayerTest, SaturateShaderMatchesCpu) {
  constexpr uint32_t n = 100000;
  std::vector<float> input(n);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> dist(-2.0f, 3.0f);
  for (float& x : input) x = dist(rng);
  // Edges and extremes. No NaN (what msm_saturate does with it is the shared header's contract, not
  // this layer's) and no subnormals (GPUs may flush them to zero, which is not what is tested here).
  const float specials[] = {0.0f,
                            -0.0f,
                            1.0f,
                            -1.0f,
                            0.5f,
                            std::nextafter(1.0f, 2.0f),
                            std::nextafter(1.0f, 0.0f),
                            FLT_MIN,
                            -FLT_MIN,
                            FLT_MAX,
                            -FLT_MAX,
                            INFINITY,
                            -INFINITY,
                            1e-30f,
                            1e30f};
  std::copy(std::begin(specials), std::end(specials), input.begin());

  Buffer src = create_buffer(ctx(), n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::device);
  Buffer dst = create_buffer(ctx(), n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::host);
  upload_buffer(ctx(), src, std::as_bytes(std::span(input)));
  Program program = create_program(ctx(), "selftest",
                                   {{MSM_BINDING_SELFTEST_SOURCE, Binding::storage_buffer},
                                    {MSM_BINDING_SELFTEST_DESTINATION, Binding::storage_buffer}},
                                   sizeof(uint32_t));
  submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
    dispatch(cmd, program, group_count(n, 64), 1, 1,
             {{MSM_BINDING_SELFTEST_SOURCE, src}, {MSM_BINDING_SELFTEST_DESTINATION, dst}}, n);
  });

  std::span<const float> out = dst.mapped<const float>();
  ASSERT_EQ(out.size(), n);
  int mismatches = 0;
  for (uint32_t i = 0; i < n; ++i)
    if (!(out[i] == msm::msm_saturate(input[i])) && ++mismatches <= 5)
      ADD_FAILURE() << "i=" << i << " x=" << input[i] << " gpu=" << out[i] << " cpu=" << msm::msm_saturate(input[i]);
  EXPECT_EQ(mismatches, 0);
  // The Device buffer reads back what was uploaded (staging path both ways).
  EXPECT_EQ(readback_buffer<float>(ctx(), src, n), input);
}

// Inputs a, b, c for msm_fma where rounding a * b first changes the result: the residuals of the
// Hankel pivots (b2 - b1 b1, b3 - b1 b2 of moments of depths in [-1, 1]), random operands over
// 2^±20 with c anywhere relative to a b, exact ties, near-ties and ties broken by a tiny c.
std::vector<float> fma_inputs(uint32_t n) {
  std::mt19937 rng(777);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> exponent(-20, 20), shift(-30, 30);
  std::vector<float> v(4 * n, 0.0f);
  for (uint32_t i = 0; i < n; ++i) {
    float a = unit(rng), b = unit(rng), c = 0.0f;
    switch (i % 6) {
    case 0: { // moments of a depth z: b2 - b1 b1, b3 - b1 b2 (of a mixture: not exactly 0)
      float z = unit(rng), w = unit(rng) * 0.5f + 0.5f;
      float b1 = w * z + (1 - w) * a, b2 = w * z * z + (1 - w) * a * a;
      a = -b1, b = i % 2 ? b1 : b2, c = i % 2 ? b2 : w * z * z * z + (1 - w) * a * a * a;
      break;
    }
    case 1: c = -(a * b); break;
    case 2:
      a = std::ldexp(a, exponent(rng)), b = std::ldexp(b, exponent(rng));
      c = std::ldexp(unit(rng), std::ilogb(a * b) + shift(rng));
      break;
    case 3: // few bits: ties of a b + c
      a = float(int(rng() % 4096) + 1), b = float(int(rng() % 8192) + 1), c = float(int(rng() % (1 << 23)) - (1 << 22));
      break;
    case 4: c = std::ldexp(unit(rng), std::ilogb(a * b) - 24 - int(rng() % 30)); break; // near ties
    default: // a b half-way between two floats, c far below: the emulation's rounding to odd decides
      a = float(4097 + 2 * int(rng() % 4000)) * 0x1p-12f, b = float(4097 + 2 * int(rng() % 4000)) * 0x1p-12f;
      c = std::ldexp(unit(rng), -20 - int(rng() % 50));
      break;
    }
    v[4 * i] = a, v[4 * i + 1] = b, v[4 * i + 2] = c;
  }
  return v;
}

// msm_fma (shared.h) in a shader (selftest_fma.comp) on the Context `ctx`; the number of results
// that differ from std::fma (bitwise; +0 and -0 alike), the first few reported as failures if `report`.
int fma_mismatches(Context& ctx, const std::vector<float>& in, const char* setting, bool report = true) {
  uint32_t n = uint32_t(in.size() / 4);
  Buffer src = create_buffer(ctx, in.size() * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::host);
  Buffer dst = create_buffer(ctx, n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::host);
  std::memcpy(src.data(), in.data(), in.size() * sizeof(float));
  Program program = create_program(ctx, "selftest_fma",
                                   {{MSM_BINDING_SELFTEST_SOURCE, Binding::storage_buffer},
                                    {MSM_BINDING_SELFTEST_DESTINATION, Binding::storage_buffer}},
                                   sizeof(uint32_t));
  submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    dispatch(cmd, program, group_count(n, 64), 1, 1,
             {{MSM_BINDING_SELFTEST_SOURCE, src}, {MSM_BINDING_SELFTEST_DESTINATION, dst}}, n);
  });
  std::span<const float> out = dst.mapped<const float>();
  int mismatches = 0;
  for (uint32_t i = 0; i < n; ++i) {
    float a = in[4 * i], b = in[4 * i + 1], c = in[4 * i + 2], want = std::fma(a, b, c);
    if (std::bit_cast<uint32_t>(out[i]) != std::bit_cast<uint32_t>(want) && !(out[i] == 0.0f && want == 0.0f) &&
        ++mismatches <= 3 && report)
      ADD_FAILURE() << setting << std::hexfloat << ": msm_fma(" << a << ", " << b << ", " << c << ") = " << out[i]
                    << ", std::fma: " << want;
  }
  return mismatches;
}

// The Context probes fma() at creation (fma_probe.comp) and every pipeline gets msm_fused_fma
// accordingly: msm_fma is then exact (std::fma bit for bit) with the native fma() where the device
// fuses it (GPUs) and with the emulation where it does not (lavapipe), and with the emulation forced
// (FmaMode::Emulated, MSM_FORCE_EMULATED_FMA) everywhere. FmaMode::Native on a device that does not
// fuse shows what the probe protects from: msm_fma rounding twice.
TEST_F(VkLayerTest, FmaProbeAndExactMsmFma) {
  std::vector<float> in = fma_inputs(50000);
  uint32_t n = uint32_t(in.size() / 4);
  std::printf("[vk] %s: fma() %s; msm_fma %s\n", ctx().info().name.c_str(), ctx().fused_fma() ? "fused" : "NOT fused",
              ctx().use_native_fma() ? "native" : "emulated");
  bool forced = [] {
    const char* v = std::getenv("MSM_FORCE_EMULATED_FMA");
    return v &&
           (std::string(v) == "1" || std::string(v) == "true" || std::string(v) == "on" || std::string(v) == "yes");
  }();
  EXPECT_EQ(ctx().use_native_fma(), ctx().fused_fma() && !forced);
  if (ctx().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU &&
      ctx().info().driver_name.find("llvmpipe") != std::string::npos) {
    EXPECT_FALSE(ctx().fused_fma()) << "lavapipe's fma() was measured unfused (a * b, then + c)";
  }
  // The shared Context, as the probe set it up.
  EXPECT_EQ(fma_mismatches(ctx(), in, ctx().use_native_fma() ? "native (probed fused)" : "emulated"), 0);

  // Each setting on a Context of its own (same device), validation on.
  auto with_mode = [&](ContextOptions::FmaMode mode, auto&& body) {
    ContextOptions options = quiet_options();
    options.fma_mode = mode;
    std::shared_ptr<ValidationLog> log;
    {
      Context other(options);
      log = other.validation_log();
      EXPECT_EQ(other.fused_fma(), ctx().fused_fma()) << "the probe is deterministic";
      body(other);
    }
    EXPECT_TRUE(test::no_validation_messages(*log));
  };
  with_mode(ContextOptions::FmaMode::emulated, [&](Context& c) {
    EXPECT_FALSE(c.use_native_fma());
    EXPECT_EQ(fma_mismatches(c, in, "forced emulation"), 0);
  });
  with_mode(ContextOptions::FmaMode::native, [&](Context& c) {
    EXPECT_TRUE(c.use_native_fma());
    if (c.fused_fma()) {
      EXPECT_EQ(fma_mismatches(c, in, "native"), 0);
    } else { // the native fma() rounds twice: many of these inputs come out wrong
      int wrong = fma_mismatches(c, in, "native", false);
      std::printf("[vk] native unfused fma(): %d of %u results differ from std::fma\n", wrong, n);
      EXPECT_GT(wrong, int(n / 10));
    }
  });
  // The environment variable forces the emulation, as FmaMode::Emulated does.
  with_env("MSM_FORCE_EMULATED_FMA", "1", [&] {
    Context forced_ctx(quiet_options());
    EXPECT_FALSE(forced_ctx.use_native_fma());
    EXPECT_EQ(forced_ctx.fused_fma(), ctx().fused_fma());
  });
}

TEST_F(VkLayerTest, PushConstantsAndEveryBindingType) {
  constexpr uint32_t W = 37, H = 23; // not multiples of the 8x8 workgroup: the bounds check matters
  struct Push {
    int32_t size[2];
    float scale;
    float layer;
  } push{{int32_t(W), int32_t(H)}, 2.0f, 3.0f};
  const float offset[4] = {0.125f, 0.25f, 0.5f, 1.0f};
  // Multiples of 1/8 with few bits: every product and sum is exact, fused or not.
  std::vector<float> source(W * H * 4), table(W * H * 4);
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      float* s = &source[(y * W + x) * 4];
      float* t = &table[(y * W + x) * 4];
      s[0] = float(x % 16) / 8.0f, s[1] = float(y % 16) / 8.0f, s[2] = float((x + y) % 7) * 0.25f, s[3] = -1.0f;
      t[0] = 0.25f * float(x % 4), t[1] = -0.5f * float(y % 3), t[2] = 1.0f, t[3] = 2.0f;
    }

  VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;
  Image source_image =
      create_image(ctx(), {W, H, format, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
  Image table_image = create_image(ctx(), {W, H, format, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
  Image result = create_image(ctx(), {W, H, format, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
  Buffer params = create_buffer(ctx(), sizeof(offset), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, Memory::host);
  Sampler sampler = create_sampler(ctx(), VK_FILTER_NEAREST);
  upload_image(ctx(), source_image, std::as_bytes(std::span(source)), VK_IMAGE_LAYOUT_UNDEFINED,
               VK_IMAGE_LAYOUT_GENERAL);
  upload_image(ctx(), table_image, std::as_bytes(std::span(table)), VK_IMAGE_LAYOUT_UNDEFINED,
               VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  upload_buffer(ctx(), params, std::as_bytes(std::span(offset)));

  Program program = create_program(ctx(), "selftest_image",
                                   {{MSM_BINDING_SELFTEST_IMAGE_SOURCE, Binding::storage_image},
                                    {MSM_BINDING_SELFTEST_IMAGE_RESULT, Binding::storage_image},
                                    {MSM_BINDING_SELFTEST_IMAGE_TABLE, Binding::sampled_image},
                                    {MSM_BINDING_SELFTEST_IMAGE_PARAMS, Binding::uniform_buffer}},
                                   sizeof(Push));
  submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
    pipeline_barrier(cmd, image_barrier(result.handle(), result.aspect(), VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                                        VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL));
    dispatch(
        cmd, program, group_count(W, 8), group_count(H, 8), 1,
        {{MSM_BINDING_SELFTEST_IMAGE_SOURCE, source_image},
         {MSM_BINDING_SELFTEST_IMAGE_RESULT, result},
         {MSM_BINDING_SELFTEST_IMAGE_TABLE, Descriptor(table_image, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sampler)},
         {MSM_BINDING_SELFTEST_IMAGE_PARAMS, params}},
        push);
  });

  std::vector<std::byte> bytes = readback_image(ctx(), result, VK_IMAGE_LAYOUT_GENERAL);
  ASSERT_EQ(bytes.size(), source.size() * sizeof(float));
  std::vector<float> out(source.size());
  std::memcpy(out.data(), bytes.data(), bytes.size());
  int mismatches = 0;
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x)
      for (uint32_t c = 0; c < 4; ++c) {
        uint32_t i = (y * W + x) * 4 + c;
        float coordinate[4] = {float(x), float(y), push.layer, 0.0f};
        float expected = source[i] * push.scale + table[i] + offset[c] + coordinate[c];
        if (out[i] != expected && ++mismatches <= 5)
          ADD_FAILURE() << "(" << x << "," << y << ")." << c << ": " << out[i] << " != " << expected;
      }
  EXPECT_EQ(mismatches, 0);
}

TEST_F(VkLayerTest, TimerScopesAreNamedOrderedAndGrow) {
  GpuTimer timer(ctx(), 2); // 4 queries per pool: the scopes below need several pools
  if (!timer.supported()) GTEST_SKIP() << "no timestamps on this queue";
  constexpr uint32_t n = 1 << 16;
  Buffer a = create_buffer(ctx(), n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Buffer b = create_buffer(ctx(), n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<float> zeros(n, 0.5f);
  upload_buffer(ctx(), a, std::as_bytes(std::span(zeros)));
  Program program = create_program(ctx(), "selftest",
                                   {{MSM_BINDING_SELFTEST_SOURCE, Binding::storage_buffer},
                                    {MSM_BINDING_SELFTEST_DESTINATION, Binding::storage_buffer}},
                                   sizeof(uint32_t));
  auto compute_to_compute = memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                           VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                           VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  const std::vector<std::string> tiny_names(12, "tiny");

  for (int frame = 0; frame < 2; ++frame) { // the second frame reuses the grown pools
    submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
      timer.reset(cmd);
      timer.begin(cmd, "frame");
      timer.begin(cmd, "shadow_depth");
      dispatch(cmd, program, group_count(n, 64), 1, 1,
               {{MSM_BINDING_SELFTEST_SOURCE, a}, {MSM_BINDING_SELFTEST_DESTINATION, b}}, n);
      timer.end(cmd);
      pipeline_barrier(cmd, compute_to_compute);
      timer.begin(cmd, "filter");
      dispatch(cmd, program, group_count(n, 64), 1, 1,
               {{MSM_BINDING_SELFTEST_SOURCE, b}, {MSM_BINDING_SELFTEST_DESTINATION, a}}, n);
      timer.end(cmd);
      pipeline_barrier(cmd, compute_to_compute);
      timer.begin(cmd, "shadow_depth");
      dispatch(cmd, program, group_count(n, 64), 1, 1,
               {{MSM_BINDING_SELFTEST_SOURCE, a}, {MSM_BINDING_SELFTEST_DESTINATION, b}}, n);
      timer.end(cmd);
      pipeline_barrier(cmd, compute_to_compute);
      timer.end(cmd);
      for (const std::string& name : tiny_names) {
        timer.begin(cmd, name);
        timer.end(cmd);
      }
    });
    TimerResults r = timer.read();
    ASSERT_EQ(r.scopes.size(), 4 + tiny_names.size());
    std::vector<std::string> names;
    for (const TimerScope& s : r.scopes) names.push_back(s.name);
    std::vector<std::string> expected = {"frame", "shadow_depth", "filter", "shadow_depth"};
    expected.insert(expected.end(), tiny_names.begin(), tiny_names.end());
    EXPECT_EQ(names, expected);
    EXPECT_EQ(r.scopes[0].depth, 0u);
    EXPECT_EQ(r.scopes[1].depth, 1u);
    EXPECT_EQ(r.scopes[4].depth, 0u);
    EXPECT_EQ(r.scopes[0].start_ms, 0.0);
    for (const TimerScope& s : r.scopes) {
      EXPECT_GE(s.start_ms, 0.0) << s.name;
      EXPECT_GE(s.ms(), 0.0) << s.name;
    }
    // Sequential scopes do not overlap; nested ones lie inside their parent.
    for (size_t i = 1; i + 1 < r.scopes.size(); ++i)
      if (i != 3) { EXPECT_LE(r.scopes[i].end_ms, r.scopes[i + 1].start_ms) << i; }
    for (size_t i = 1; i <= 3; ++i) {
      EXPECT_GE(r.scopes[i].start_ms, r.scopes[0].start_ms);
      EXPECT_LE(r.scopes[i].end_ms, r.scopes[0].end_ms);
    }
    EXPECT_GT(r.scopes[0].ms(), 0.0); // three dispatches of 65536 invocations take some time
    EXPECT_EQ(r.count("shadow_depth"), 2u);
    EXPECT_DOUBLE_EQ(r.total("shadow_depth"), r.scopes[1].ms() + r.scopes[3].ms());
    EXPECT_EQ(r.total("absent"), 0.0);
    auto totals = r.totals();
    ASSERT_EQ(totals.size(), 4u);
    EXPECT_EQ(totals[1].first, "shadow_depth");
    EXPECT_EQ(totals[3].first, "tiny");
  }

  // Misuse is an exception, not a validation error or a hang.
  submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
    EXPECT_THROW(timer.begin(cmd, "no reset"), std::logic_error);
    timer.reset(cmd);
    EXPECT_THROW(timer.end(cmd), std::logic_error);
    timer.begin(cmd, "open");
    EXPECT_THROW(timer.read(), std::logic_error);
    timer.end(cmd);
  });
  EXPECT_EQ(timer.read().scopes.size(), 1u);
}

// An allocation larger than the device's heap (a 2D array of RGBA32F 8192² layers, 1 GiB each,
// one more than the heap holds) is an Error naming the size and the heap, not an abort or a
// driver's undefined behaviour; the device stays usable.
TEST_F(VkLayerTest, AllocationLargerThanTheHeapIsAnError) {
  const VkPhysicalDeviceMemoryProperties& props = ctx().memory_properties();
  VkDeviceSize largest = 0;
  for (uint32_t i = 0; i < props.memoryHeapCount; ++i) largest = std::max(largest, props.memoryHeaps[i].size);
  const uint32_t layers = uint32_t(largest >> 30) + 1;
  // 1 GiB layers: a heap of more than maxImageArrayLayers GiB (2048 on lavapipe and common GPUs)
  // would need another image shape here; fail rather than pass without testing.
  ASSERT_LE(layers, ctx().properties().limits.maxImageArrayLayers) << "the heap exceeds the largest image";
  try {
    create_image(ctx(), {.width = 8192,
                         .height = 8192,
                         .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                         .usage = VK_IMAGE_USAGE_SAMPLED_BIT,
                         .layers = layers});
    FAIL() << "an image larger than every heap was allocated";
  } catch (const Error& e) {
    EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY);
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("the device is out of memory: ", 0), 0u) << what;
    EXPECT_NE(what.find(" MiB asked of a heap of "), std::string::npos) << what;
  }
  EXPECT_NO_THROW(create_image(
      ctx(),
      {.width = 16, .height = 16, .format = VK_FORMAT_R32G32B32A32_SFLOAT, .usage = VK_IMAGE_USAGE_SAMPLED_BIT}));
}

TEST_F(VkLayerTest, ArgumentErrorsThrowBeforeAnythingIsRecorded) {
  Buffer buffer = create_buffer(ctx(), 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Program program = create_program(ctx(), "selftest",
                                   {{MSM_BINDING_SELFTEST_SOURCE, Binding::storage_buffer},
                                    {MSM_BINDING_SELFTEST_DESTINATION, Binding::storage_buffer}},
                                   4);
  EXPECT_EQ(program.name(), "selftest");
  EXPECT_EQ(program.bindings().size(), 2u);
  submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
    const std::initializer_list<DescriptorAt> both = {{MSM_BINDING_SELFTEST_SOURCE, buffer},
                                                      {MSM_BINDING_SELFTEST_DESTINATION, buffer}};
    EXPECT_THROW(dispatch(cmd, program, 1, 1, 1, {{MSM_BINDING_SELFTEST_SOURCE, buffer}}, 1u), std::invalid_argument);
    EXPECT_THROW(dispatch(cmd, program, 1, 1, 1, both), std::invalid_argument);
    EXPECT_THROW(dispatch(cmd, program, 1, 1, 1, both, uint64_t(1)), std::invalid_argument);
    // Binding numbers with a gap or given twice: no positional list to push.
    EXPECT_THROW(dispatch(cmd, program, 1, 1, 1, {{0, buffer}, {2, buffer}}, 1u), std::invalid_argument);
    EXPECT_THROW(dispatch(cmd, program, 1, 1, 1, {{1, buffer}, {1, buffer}}, 1u), std::invalid_argument);
  });
  EXPECT_THROW(create_program(ctx(), "selftest", {{MSM_BINDING_SELFTEST_SOURCE, Binding::storage_buffer}}, 6),
               std::invalid_argument);
  EXPECT_THROW(create_program(ctx(), "selftest", {{1, Binding::storage_buffer}}, 4), std::invalid_argument);
  EXPECT_THROW(bindings_at({{0, Binding::storage_buffer}, {0, Binding::storage_image}}), std::invalid_argument);
  // Given in any order, each lands at its number.
  EXPECT_EQ(bindings_at({{1, Binding::storage_image}, {0, Binding::uniform_buffer}}),
            (std::vector<Binding>{Binding::uniform_buffer, Binding::storage_image}));
  const uint32_t not_spirv[] = {1, 2, 3};
  EXPECT_THROW(create_program(ctx(), not_spirv, "junk", {}), std::invalid_argument);
  EXPECT_THROW(create_program(ctx(), "no_such_shader", {}), std::runtime_error);
  // An exception while recording leaves nothing behind (the command buffer is freed, unsubmitted).
  EXPECT_THROW(submit_and_wait(ctx(), [](VkCommandBuffer) { throw std::runtime_error("recording failed"); }),
               std::runtime_error);
  std::byte bytes[16]{};
  EXPECT_THROW(upload_buffer(ctx(), buffer, bytes, 56), std::out_of_range);
  EXPECT_THROW(readback_buffer(ctx(), buffer, bytes, 64), std::out_of_range);
}

TEST_F(VkLayerTest, BuffersRoundTripAtOffsets) {
  std::vector<uint32_t> words(256);
  for (uint32_t i = 0; i < words.size(); ++i) words[i] = i * 2654435761u;
  for (Memory memory : {Memory::device, Memory::host}) {
    Buffer buffer = create_buffer(ctx(), 4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, memory);
    EXPECT_EQ(buffer.memory(), memory);
    EXPECT_EQ(buffer.data() != nullptr, memory == Memory::host);
    upload_buffer(ctx(), buffer, std::as_bytes(std::span(words)), 1024);
    EXPECT_EQ(readback_buffer<uint32_t>(ctx(), buffer, words.size(), 1024), words);
    Buffer moved = std::move(buffer); // move-only handles: the moved-from one owns nothing
    EXPECT_FALSE(buffer);             // NOLINT(bugprone-use-after-move): the moved-from state is what is tested
    EXPECT_EQ(readback_buffer<uint32_t>(ctx(), moved, 4, 1024 + 8),
              std::vector<uint32_t>(words.begin() + 2, words.begin() + 6));
  }
}

TEST_F(VkLayerTest, ImagesWithMipsLayersSamplesAndViews) {
  // Layers round trip through upload/readback.
  Image layered = create_image(
      ctx(), {.width = 16,
              .height = 8,
              .format = VK_FORMAT_R32_SFLOAT,
              .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
              .layers = 3});
  std::vector<float> texels(16 * 8 * 3);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = float(i) * 0.5f;
  upload_image(ctx(), layered, std::as_bytes(std::span(texels)), VK_IMAGE_LAYOUT_UNDEFINED,
               VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  std::vector<std::byte> bytes = readback_image(ctx(), layered, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  ASSERT_EQ(bytes.size(), texels.size() * sizeof(float));
  EXPECT_EQ(std::memcmp(bytes.data(), texels.data(), bytes.size()), 0);

  // A mip chain with one view per mip, as a reduction pass would use.
  Image mips = create_image(ctx(), {.width = 64,
                                    .height = 64,
                                    .format = VK_FORMAT_R16G16B16A16_SFLOAT,
                                    .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT,
                                    .mip_levels = 7});
  EXPECT_NE(mips.view(), VK_NULL_HANDLE);
  std::vector<ImageView> mip_views;
  for (uint32_t mip = 0; mip < 7; ++mip)
    mip_views.push_back(create_image_view(ctx(), mips.handle(), mips.format(), VK_IMAGE_ASPECT_COLOR_BIT,
                                          VK_IMAGE_VIEW_TYPE_2D, mip, 1));

  // A multisampled depth target and a comparison sampler for shadow lookups.
  VkSampleCountFlags counts = ctx().properties().limits.framebufferDepthSampleCounts;
  VkSampleCountFlagBits samples = (counts & VK_SAMPLE_COUNT_4_BIT) ? VK_SAMPLE_COUNT_4_BIT : VK_SAMPLE_COUNT_1_BIT;
  Image depth = create_image(ctx(), {.width = 32,
                                     .height = 32,
                                     .format = VK_FORMAT_D32_SFLOAT,
                                     .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                                     .samples = samples});
  EXPECT_EQ(depth.aspect(), VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT));
  Sampler shadow_sampler =
      create_sampler(ctx(), VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER, VK_COMPARE_OP_LESS_OR_EQUAL);
  EXPECT_TRUE(shadow_sampler);

  // Transfer-only images get no view; move assignment releases the old image first.
  Image plain = create_image(
      ctx(), {.width = 4, .height = 4, .format = VK_FORMAT_R8G8B8A8_UNORM, .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT});
  EXPECT_EQ(plain.view(), VK_NULL_HANDLE);
  plain = std::move(depth);
  EXPECT_FALSE(depth); // NOLINT(bugprone-use-after-move): the moved-from state is what is tested
  EXPECT_EQ(plain.format(), VK_FORMAT_D32_SFLOAT);
}

} // namespace
} // namespace msm::vk
