// msm::gpu::SatBuilder on the Vulkan device (MSM_DEVICE; lavapipe here), validation and
// synchronization validation on (VulkanTest: any message fails):
//  - every scheme (rows then columns, scan rows, subgroup rows, subgroup rows and columns; JCGT
//    Appendix C blocks) produces exactly build_sat_cpu's
//    table, bitwise, for float and UNORM16 moment images, two- and four-channel formats, sizes
//    that are not multiples of the 8 × 8 blocks nor of the 64-thread groups (61 × 47, 250 × 3),
//    256², 1024² (blocks and subgroup schemes), small and large n_t; and build_sat_cpu itself equals 64-bit running
//    sums taken modulo 2^32;
//  - the six-moment overload (two images, RGBA32F + RG32F) fills both tables;
//  - the copy shaders that msm_sat_timing times beside the schemes (sat_copy.h) copy every texel,
//    bitwise, and touch nothing else, at sizes that are not multiples of their groups;
//  - the shared queries (sat.h's 4- and 16-lookup queries) and soft.h's whole per-pixel flow, the
//    functions the renderer's shading calls (mssm4, mssm6, vssm, cssm8, cssm16), in a shader
//    (shaders/test/sat_queries.comp, via sat_queries.h) agree with the same code on the CPU; and the
//    renderer's shaders compose that flow nowhere else.
#include "msm/gpu/sat_builder.h"
#include "msm/quantize.h"
#include "msm/techniques.h"
#include "msm/test/vulkan_test.h"
#include "msm/vk/vk.h"
#include "sat_copy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "shaders/test/sat_queries.h"

namespace {

using namespace msm;
using msm::gpu::SatBuilder;
using Scheme = SatBuilder::Scheme;

class SatBuilderTest : public vk::test::VulkanTest {};

// Random Θ4* moments of random depths; every 7th texel at (1,1,1,1) and every 11th slightly out of
// [0,1] (clamped by the quantization), so running sums wrap and every branch is taken.
std::vector<vec4> random_moments(std::mt19937_64& rng, int width, int height) {
  std::uniform_real_distribution<float> depth(-1.0f, 1.0f);
  std::vector<vec4> m(size_t(width) * size_t(height));
  for (size_t i = 0; i < m.size(); ++i) {
    m[i] = msm_theta4_star(msm_moments4(depth(rng)));
    if (i % 7 == 0) m[i] = vec4(1.0f);
    if (i % 11 == 0) m[i] = vec4(-1e-3f, 1.0f + 1e-3f, m[i][2], m[i][3]);
  }
  return m;
}

// 64-bit running sums of the quantized texels, reduced modulo 2^32: an independent reference.
std::vector<uvec4> reference_table(const std::vector<vec4>& m, int width, int height, int nt) {
  uint scale = msm_sat_scale(nt);
  std::vector<uint64_t> s(m.size() * 4, 0);
  std::vector<uvec4> out(m.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      size_t i = size_t(y) * size_t(width) + size_t(x);
      uvec4 q = msm_sat_quantize(m[i], scale);
      for (int c = 0; c < 4; ++c) {
        uint64_t v = q[c];
        if (x > 0) v += s[(i - 1) * 4 + size_t(c)];
        if (y > 0) v += s[(i - size_t(width)) * 4 + size_t(c)];
        if (x > 0 && y > 0) v -= s[(i - size_t(width) - 1) * 4 + size_t(c)];
        s[i * 4 + size_t(c)] = v;
        out[i][c] = uint32_t(v & 0xFFFFFFFFull);
      }
    }
  return out;
}

vk::Image moment_image(vk::Context& ctx, VkFormat format, int width, int height) {
  return vk::create_image(ctx, vk::ImageDesc{.width = uint32_t(width),
                                             .height = uint32_t(height),
                                             .format = format,
                                             .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
}
vk::Image table_image(vk::Context& ctx, int width, int height, VkFormat format = VK_FORMAT_R32G32B32A32_UINT) {
  return vk::create_image(ctx, vk::ImageDesc{.width = uint32_t(width),
                                             .height = uint32_t(height),
                                             .format = format,
                                             .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
}

// Uploads the moments in `format` and returns the values as the CPU sees them (UNORM16: decoded by
// msm_unpack_unorm16x4; two-channel formats: z and w are 0).
std::vector<vec4> upload(vk::Context& ctx, const vk::Image& image, const std::vector<vec4>& m) {
  std::vector<vec4> seen(m.size());
  std::vector<std::byte> bytes;
  VkFormat format = image.format();
  for (size_t i = 0; i < m.size(); ++i) {
    if (format == VK_FORMAT_R32G32B32A32_SFLOAT || format == VK_FORMAT_R32G32_SFLOAT) {
      int channels = format == VK_FORMAT_R32G32_SFLOAT ? 2 : 4;
      for (int c = 0; c < channels; ++c) {
        float v = m[i][c];
        const std::byte* b = reinterpret_cast<const std::byte*>(&v);
        bytes.insert(bytes.end(), b, b + 4);
      }
      seen[i] = channels == 2 ? vec4(m[i][0], m[i][1], 0.0f, 0.0f) : m[i];
    } else {
      bool two = format == VK_FORMAT_R16G16_UNORM;
      vec4 v = two ? vec4(m[i][0], m[i][1], 0.0f, 0.0f) : m[i];
      uvec2 p = msm_pack_unorm16x4(v);
      const std::byte* b = reinterpret_cast<const std::byte*>(&p);
      bytes.insert(bytes.end(), b, b + (two ? 4 : 8));
      seen[i] = msm_unpack_unorm16x4(p);
    }
  }
  vk::upload_image(ctx, image, bytes, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
  return seen;
}

std::vector<uvec4> read_table(vk::Context& ctx, const vk::Image& table) {
  std::vector<std::byte> bytes = vk::readback_image(ctx, table, VK_IMAGE_LAYOUT_GENERAL);
  std::vector<uvec4> out(bytes.size() / sizeof(uvec4));
  std::memcpy(static_cast<void*>(out.data()), bytes.data(), bytes.size());
  return out;
}

struct Case {
  int width, height, nt;
  VkFormat format;
  bool rows_then_columns; // the block and subgroup schemes always run
};

// Bitwise equality with the CPU table, every scheme.
TEST_F(SatBuilderTest, BothSchemesEqualTheCpuTableBitwise) {
  SatBuilder builder(ctx());
  std::mt19937_64 rng(31);
  const Case cases[] = {
      {61, 47, 27 * 27, VK_FORMAT_R32G32B32A32_SFLOAT, true},
      {61, 47, 33 * 33, VK_FORMAT_R16G16B16A16_UNORM, true},
      {250, 3, 100, VK_FORMAT_R32G32_SFLOAT, true}, // n_t < 256: scale above 2^24
      {13, 70, 9, VK_FORMAT_R16G16_UNORM, true},
      {256, 256, 27 * 27, VK_FORMAT_R32G32B32A32_SFLOAT, true},
      {256, 256, 64 * 64, VK_FORMAT_R16G16B16A16_UNORM, true},
      {1024, 1024, 27 * 27, VK_FORMAT_R32G32B32A32_SFLOAT, false},
  };
  for (const Case& c : cases) {
    std::vector<vec4> m = random_moments(rng, c.width, c.height);
    vk::Image moments = moment_image(ctx(), c.format, c.width, c.height);
    std::vector<vec4> seen = upload(ctx(), moments, m);
    std::vector<uvec4> cpu = gpu::build_sat_cpu(seen, c.width, c.height, c.nt);
    ASSERT_EQ(cpu, reference_table(seen, c.width, c.height, c.nt)) << c.width << "x" << c.height;
    for (Scheme scheme : {Scheme::rows_then_columns, Scheme::scan_rows_then_columns, Scheme::subgroup_rows_then_columns,
                          Scheme::subgroup_rows_and_columns, Scheme::blocks}) {
      bool subgroup = scheme == Scheme::subgroup_rows_then_columns || scheme == Scheme::subgroup_rows_and_columns;
      if (scheme != Scheme::blocks && !subgroup && !c.rows_then_columns) continue;
      vk::Image table = table_image(ctx(), c.width, c.height);
      vk::GpuTimer timer(ctx());
      vk::submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
        timer.reset(cmd);
        builder.record(cmd, moments, table, c.nt, scheme, &timer);
      });
      std::vector<uvec4> gpu = read_table(ctx(), table);
      ASSERT_EQ(gpu.size(), cpu.size());
      size_t mismatches = 0, first = gpu.size();
      for (size_t i = 0; i < gpu.size(); ++i)
        if (gpu[i] != cpu[i]) {
          ++mismatches;
          first = std::min(first, i);
        }
      vk::TimerResults times = timer.read();
      bool blocks = scheme == Scheme::blocks;
      EXPECT_EQ(times.count(blocks ? "sat_blocks" : "sat_rows"), 1u);
      EXPECT_EQ(times.count("sat_columns"), blocks ? 0u : 1u);
      std::printf("[sat-builder] %dx%d n_t %d format %d %s: %zu of %zu texels differ\n", c.width, c.height, c.nt,
                  int(c.format),
                  blocks                                         ? "blocks"
                  : scheme == Scheme::scan_rows_then_columns     ? "scan rows+columns"
                  : scheme == Scheme::subgroup_rows_then_columns ? "subgroup rows+columns"
                  : scheme == Scheme::subgroup_rows_and_columns  ? "subgroup rows+subgroup columns"
                                                                 : "rows+columns",
                  mismatches, gpu.size());
      EXPECT_EQ(mismatches, 0u) << "first at texel " << first % size_t(c.width) << "," << first / size_t(c.width);
    }
  }
}

// The copy shaders of msm_sat_timing (sat_copy.h): each writes exactly its source into its
// destination, every texel (a sentinel elsewhere would show), at sizes that are not multiples of
// their groups of 64 or 256 texels: their times are those of whole copies.
TEST_F(SatBuilderTest, CopyShadersCopyEveryTexel) {
  namespace sc = gpu::sat_copy;
  const std::vector<vk::Program> programs = sc::create_programs(ctx());
  const vk::Sampler nearest = vk::create_sampler(ctx(), VK_FILTER_NEAREST);
  std::mt19937_64 rng(18);
  std::uniform_real_distribution<float> value(-1e3f, 1e3f); // finite floats: texelFetch returns their bits
  for (auto [w, h] : {std::pair{61, 47}, std::pair{300, 3}, std::pair{13, 70}}) {
    const size_t texels = size_t(w) * size_t(h);
    std::vector<vec4> floats(texels);
    for (vec4& f : floats) f = vec4(value(rng), value(rng), value(rng), value(rng));
    std::vector<uvec4> expected(texels), sentinel(texels, uvec4(0xDEADBEEFu));
    std::memcpy(static_cast<void*>(expected.data()), floats.data(), texels * sizeof(uvec4));
    const auto bytes = std::as_bytes(std::span(expected));
    const auto sentinel_bytes = std::as_bytes(std::span(sentinel));
    auto image = [&](VkFormat format, VkImageUsageFlags usage) {
      return vk::create_image(
          ctx(), vk::ImageDesc{.width = uint32_t(w),
                               .height = uint32_t(h),
                               .format = format,
                               .usage = usage | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    };
    vk::Image src_image = image(VK_FORMAT_R32G32B32A32_UINT, VK_IMAGE_USAGE_STORAGE_BIT);
    vk::Image src_floats = image(VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_USAGE_SAMPLED_BIT);
    vk::upload_image(ctx(), src_image, bytes, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    vk::upload_image(ctx(), src_floats, bytes, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    vk::Buffer src_buffer = vk::create_buffer(ctx(), bytes.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::upload_buffer(ctx(), src_buffer, bytes);
    for (int i = 0; i < sc::count; ++i) {
      const sc::Shader& s = sc::shaders[i];
      vk::Image dst_image = image(VK_FORMAT_R32G32B32A32_UINT, VK_IMAGE_USAGE_STORAGE_BIT);
      vk::Buffer dst_buffer = vk::create_buffer(ctx(), bytes.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
      const bool buffer = s.kind == sc::Kind::buffer;
      if (buffer)
        vk::upload_buffer(ctx(), dst_buffer, sentinel_bytes);
      else
        vk::upload_image(ctx(), dst_image, sentinel_bytes, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
      vk::submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
        const vk::Descriptor src = buffer ? vk::Descriptor(src_buffer)
                                   : s.kind == sc::Kind::fetch
                                       ? vk::Descriptor(src_floats, VK_IMAGE_LAYOUT_GENERAL, nearest)
                                       : vk::Descriptor(src_image, VK_IMAGE_LAYOUT_GENERAL);
        const vk::Descriptor dst =
            buffer ? vk::Descriptor(dst_buffer) : vk::Descriptor(dst_image, VK_IMAGE_LAYOUT_GENERAL);
        sc::record(cmd, programs[size_t(i)], s, uint32_t(w), uint32_t(h), src, dst);
      });
      std::vector<uvec4> got =
          buffer ? vk::readback_buffer<uvec4>(ctx(), dst_buffer, texels) : read_table(ctx(), dst_image);
      ASSERT_EQ(got.size(), texels);
      size_t wrong = 0;
      for (size_t t = 0; t < texels; ++t) wrong += got[t] != expected[t];
      EXPECT_EQ(wrong, 0u) << s.name << ", " << w << "x" << h;
    }
  }
}

// Six moments: two images (Θ6* split: RGBA32F + RG32F) in one call, both schemes.
TEST_F(SatBuilderTest, SixMomentTablesInOneCall) {
  SatBuilder builder(ctx());
  std::mt19937_64 rng(32);
  std::uniform_real_distribution<float> depth(-1.0f, 1.0f);
  const int w = 45, h = 38, nt = 27 * 27;
  std::vector<vec4> a(size_t(w * h)), b(size_t(w * h));
  for (size_t i = 0; i < a.size(); ++i) {
    SatTexels6 t = msm_sat_split6(msm_theta6_star(msm_moments6(depth(rng))));
    a[i] = t.a;
    b[i] = t.b;
  }
  vk::Image ma = moment_image(ctx(), VK_FORMAT_R32G32B32A32_SFLOAT, w, h);
  vk::Image mb = moment_image(ctx(), VK_FORMAT_R32G32_SFLOAT, w, h);
  std::vector<vec4> sa = upload(ctx(), ma, a), sb = upload(ctx(), mb, b);
  for (Scheme scheme : {Scheme::rows_then_columns, Scheme::scan_rows_then_columns, Scheme::subgroup_rows_then_columns,
                        Scheme::subgroup_rows_and_columns, Scheme::blocks}) {
    vk::Image ta = table_image(ctx(), w, h), tb = table_image(ctx(), w, h);
    const gpu::SatImage moments[] = {ma, mb};
    const gpu::SatImage tables[] = {ta, tb};
    vk::submit_and_wait(ctx(), [&](VkCommandBuffer cmd) { builder.record(cmd, moments, tables, nt, scheme); });
    EXPECT_EQ(read_table(ctx(), ta), gpu::build_sat_cpu(sa, w, h, nt));
    EXPECT_EQ(read_table(ctx(), tb), gpu::build_sat_cpu(sb, w, h, nt));
  }
}

// Two-channel moments into RG32_UINT tables (half the memory of RGBA32_UINT): the (r, g) of the
// CPU table, bitwise, both schemes, float and UNORM16 moments.
TEST_F(SatBuilderTest, RgTablesHoldTheRgOfTheCpuTable) {
  SatBuilder builder(ctx());
  std::mt19937_64 rng(34);
  const Case cases[] = {{61, 47, 27 * 27, VK_FORMAT_R32G32_SFLOAT, true},
                        {130, 9, 100, VK_FORMAT_R16G16_UNORM, true},
                        {256, 256, 27 * 27, VK_FORMAT_R32G32_SFLOAT, true}};
  for (const Case& c : cases) {
    std::vector<vec4> m = random_moments(rng, c.width, c.height);
    vk::Image moments = moment_image(ctx(), c.format, c.width, c.height);
    std::vector<uvec4> cpu = gpu::build_sat_cpu(upload(ctx(), moments, m), c.width, c.height, c.nt);
    for (Scheme scheme : {Scheme::rows_then_columns, Scheme::scan_rows_then_columns, Scheme::subgroup_rows_then_columns,
                          Scheme::subgroup_rows_and_columns, Scheme::blocks}) {
      vk::Image table = table_image(ctx(), c.width, c.height, VK_FORMAT_R32G32_UINT);
      vk::submit_and_wait(ctx(), [&](VkCommandBuffer cmd) { builder.record(cmd, moments, table, c.nt, scheme); });
      std::vector<std::byte> bytes = vk::readback_image(ctx(), table, VK_IMAGE_LAYOUT_GENERAL);
      ASSERT_EQ(bytes.size(), cpu.size() * 8);
      size_t mismatches = 0;
      for (size_t i = 0; i < cpu.size(); ++i) {
        uint32_t rg[2];
        std::memcpy(rg, bytes.data() + 8 * i, 8);
        mismatches += rg[0] != cpu[i].x || rg[1] != cpu[i].y;
      }
      EXPECT_EQ(mismatches, 0u) << c.width << "x" << c.height << ", scheme " << int(scheme);
    }
  }
}

// The subgroup schemes run as themselves exactly where the device reports subgroup arithmetic (with
// the basic and shuffle operations) in compute shaders, else as scan_rows_then_columns. On lavapipe
// (subgroup size 8, arithmetic in compute) they run: the bitwise tests above test the subgroup shaders.
TEST_F(SatBuilderTest, SubgroupSchemesRunWhereTheDeviceHasSubgroupArithmetic) {
  SatBuilder builder(ctx());
  VkPhysicalDeviceVulkan11Properties v11{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES};
  VkPhysicalDeviceProperties2 p2{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &v11};
  vkGetPhysicalDeviceProperties2(ctx().physical_device(), &p2);
  const bool has = (v11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                   (v11.subgroupSupportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) &&
                   (v11.subgroupSupportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_BIT);
  std::printf("[sat-builder] %s: subgroup size %u, arithmetic in compute: %s\n", ctx().info().name.c_str(),
              v11.subgroupSize, has ? "yes" : "no");
  EXPECT_EQ(builder.subgroup_arithmetic(), has);
  for (Scheme s : {Scheme::subgroup_rows_then_columns, Scheme::subgroup_rows_and_columns})
    EXPECT_EQ(builder.effective(s), has ? s : Scheme::scan_rows_then_columns);
  for (Scheme s : {Scheme::rows_then_columns, Scheme::scan_rows_then_columns, Scheme::blocks})
    EXPECT_EQ(builder.effective(s), s);
  if (ctx().info().driver_name == "llvmpipe") { EXPECT_TRUE(has) << "lavapipe has subgroup arithmetic in compute"; }
}

TEST_F(SatBuilderTest, RejectsBadImages) {
  SatBuilder builder(ctx());
  vk::Image moments = moment_image(ctx(), VK_FORMAT_R32G32B32A32_SFLOAT, 16, 16);
  vk::Image wrong_size = table_image(ctx(), 16, 15);
  vk::Image table = table_image(ctx(), 16, 16);
  vk::Image not_moments = moment_image(ctx(), VK_FORMAT_R8G8B8A8_UNORM, 16, 16);
  vk::submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
    EXPECT_THROW(builder.record(cmd, moments, wrong_size, 729, Scheme::blocks), std::invalid_argument);
    EXPECT_THROW(builder.record(cmd, not_moments, table, 729, Scheme::blocks), std::invalid_argument);
    EXPECT_THROW(builder.record(cmd, moments, moments, 729, Scheme::blocks), std::invalid_argument);
    EXPECT_THROW(builder.record(cmd, moments, table, 0, Scheme::blocks), std::invalid_argument);
    // An RG table cannot hold four moments.
    vk::Image rg = table_image(ctx(), 16, 16, VK_FORMAT_R32G32_UINT);
    EXPECT_THROW(builder.record(cmd, moments, rg, 729, Scheme::blocks), std::invalid_argument);
  });
  EXPECT_THROW(gpu::build_sat_cpu(std::vector<vec4>(10), 3, 3, 729), std::invalid_argument);
}

// The queries on the device: sat.h's 4-lookup rectangle sum (bitwise), the nine-region box filter
// and soft.h's whole flow (msm_soft_moment_flow: search, the technique's blocker estimator, umbra
// early-out, penumbra, nine-region filter, the receiver plane's bias, the bound, over-darkening;
// msm_soft_cssm_flow likewise) against the same code on the CPU (sat_queries.h), for each soft
// technique with its default parameters, on a scene of occluder rectangles at several depths over
// a sloped receiver. Differences come from float division (2.5 ulp on Vulkan), the device's
// contractions and sqrt; msm_fma is exact on both. Measured (lavapipe, 20000 queries each): rect
// sums and filtered values bitwise everywhere; shadow max 7.5e-7 (mssm4), 6e-8 (vssm), 1.0e-6 and
// 1.7e-6 (cssm8, cssm16), blocker depth bitwise or within 2.4e-7; mssm6 (Eq. 19's roots): depth
// max 1.0e-5, shadow max 1.8e-3, 15 fragments beyond 1e-3. Tolerances (for other devices): 1e-6
// (filtered), 1e-3 (depth, shadow) with at most 0.2% of fragments beyond, for a path taken
// differently at a threshold (umbra, roots at zf).
struct SoftFlowCase {
  const char* name;
  int technique;
};
class SoftFlowOnTheDevice : public vk::test::VulkanTest, public ::testing::WithParamInterface<SoftFlowCase> {};

TEST_P(SoftFlowOnTheDevice, AgreesWithTheCpu) {
  const int technique = GetParam().technique;
  const bool cssm = msm_technique_is_cssm(technique);
  const int moments = cssm ? 0 : (technique == MSM_TECH_MSSM6 ? 6 : (technique == MSM_TECH_VSSM ? 2 : 4));
  const int frequencies = msm_technique_cssm_frequencies(technique), tiles = msm_technique_tiles(technique);
  const vec4 params = msm_technique_default_params(technique);
  std::mt19937_64 rng(33);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const int w = 128, h = 96, width = 27, nt = width * width;
  const uint scale = msm_sat_scale(nt);
  // Receiver at [0,1] depth 0.8 with a slope along x, occluders: random rectangles at 0.1 .. 0.7.
  const int centre = w / 2; // the receiver's slope pivots on the middle column
  const float slope = 0.0005f;
  const auto at = [w](int x, int y) { return size_t(y) * size_t(w) + size_t(x); };
  std::vector<float> depth(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) depth[at(x, y)] = 0.8f + slope * float(x - centre);
  for (int k = 0; k < 25; ++k) { // the first five large enough to hold umbrae
    int x0 = int(unit(rng) * w), y0 = int(unit(rng) * h), x1 = x0 + 2 + int(unit(rng) * (k < 5 ? 60 : 30)),
        y1 = y0 + 2 + int(unit(rng) * (k < 5 ? 50 : 20));
    float z = 0.1f + 0.6f * unit(rng);
    for (int y = y0; y < std::min(y1, h); ++y)
      for (int x = x0; x < std::min(x1, w); ++x) depth[at(x, y)] = std::min(depth[at(x, y)], z);
  }
  // The tables as the renderer fills them: the technique's texels (CSSM: its tiles stacked along y).
  std::vector<vec4> a(depth.size() * size_t(tiles)), b(depth.size());
  for (size_t i = 0; i < depth.size(); ++i) {
    MsmTexel texel = msm_technique_generate(technique, depth[i], params);
    a[i] = texel.a;
    b[i] = texel.b;
    for (int t = 0; cssm && t < tiles; ++t)
      a[size_t(t) * depth.size() + i] = msm_cssm_generate(depth[i], t, frequencies);
  }
  const std::vector<uvec4> cpu0 = gpu::build_sat_cpu(a, w, h * tiles, nt), cpu1 = gpu::build_sat_cpu(b, w, h, nt);
  auto uploaded_table = [&](const std::vector<uvec4>& table, int rows) {
    vk::Image image =
        vk::create_image(ctx(), vk::ImageDesc{.width = uint32_t(w),
                                              .height = uint32_t(rows),
                                              .format = VK_FORMAT_R32G32B32A32_UINT,
                                              .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    std::vector<std::byte> bytes(table.size() * sizeof(uvec4));
    std::memcpy(bytes.data(), table.data(), bytes.size());
    vk::upload_image(ctx(), image, bytes, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    return image;
  };
  vk::Image table0 = uploaded_table(cpu0, h * tiles), table1 = uploaded_table(cpu1, h);

  static_assert(sizeof(SatQuery) == 32 && sizeof(SatQueryResult) == 48);
  static_assert(sizeof(SatQueryPush) == 64 && offsetof(SatQueryPush, spread) == 16 &&
                offsetof(SatQueryPush, moments) == 28 && offsetof(SatQueryPush, params) == 32 &&
                offsetof(SatQueryPush, cssm) == 48); // std430, as sat_queries.comp reads them
  const uint32_t count = 20000;
  std::vector<SatQuery> queries(count);
  for (SatQuery& q : queries) {
    vec2 extent(0.01f + 25.99f * unit(rng) * unit(rng), 0.01f + 25.99f * unit(rng));
    vec2 lo(unit(rng) * (float(w) - extent.x), unit(rng) * (float(h) - extent.y));
    int px = int(unit(rng) * w), py = int(unit(rng) * h);
    q.region = vec4(lo, lo + extent);
    q.fragment = vec4(float(px) + 0.5f, float(py) + 0.5f, 0.8f + slope * float(px - centre), 2.0f * slope);
  }
  vk::Buffer query_buffer =
      vk::create_buffer(ctx(), sizeof(SatQuery) * count, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
  vk::Buffer result_buffer =
      vk::create_buffer(ctx(), sizeof(SatQueryResult) * count, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
  static_assert(std::is_standard_layout_v<SatQuery>); // glm vectors: see gpu_math_test.cpp's KernelIO
  // NOLINTNEXTLINE(bugprone-undefined-memory-manipulation): standard layout, asserted above
  std::memcpy(query_buffer.data(), queries.data(), sizeof(SatQuery) * count);
  vk::Program program = vk::create_program(ctx(), "sat_queries.comp",
                                           {{MSM_BINDING_SAT_QUERIES_TABLE0, vk::Binding::storage_image},
                                            {MSM_BINDING_SAT_QUERIES_TABLE1, vk::Binding::storage_image},
                                            {MSM_BINDING_SAT_QUERIES_QUERIES, vk::Binding::storage_buffer},
                                            {MSM_BINDING_SAT_QUERIES_RESULTS, vk::Binding::storage_buffer}},
                                           sizeof(SatQueryPush));
  const SatQueryPush push{ivec2(w, h), scale, width, vec2(30.0f), count, moments, params, ivec4(frequencies, 0, 0, 0)};
  vk::submit_and_wait(ctx(), [&](VkCommandBuffer cmd) {
    vk::dispatch(cmd, program, vk::group_count(count, 64), 1, 1,
                 {{MSM_BINDING_SAT_QUERIES_TABLE0, vk::Descriptor(table0)},
                  {MSM_BINDING_SAT_QUERIES_TABLE1, vk::Descriptor(table1)},
                  {MSM_BINDING_SAT_QUERIES_QUERIES, query_buffer},
                  {MSM_BINDING_SAT_QUERIES_RESULTS, result_buffer}},
                 push);
  });
  std::vector<SatQueryResult> gpu(count);
  std::memcpy(static_cast<void*>(gpu.data()), result_buffer.data(), sizeof(SatQueryResult) * count);

  const auto fetch = [&](int x, int y, int table) {
    int row = cssm ? y + table * h : y;
    if (x < 0 || row < 0) return uvec4(0u);
    return (!cssm && table == 1 ? cpu1 : cpu0)[at(x, row)];
  };
  double filtered_max = 0.0, depth_max = 0.0, shadow_max = 0.0;
  int rect_mismatches = 0, beyond = 0, early = 0, penumbra = 0, lit = 0;
  for (uint32_t i = 0; i < count; ++i) {
    SatQueryResult c = msm_test_sat_query(fetch, queries[i], push);
    rect_mismatches += c.rect_sum != gpu[i].rect_sum ? 1 : 0;
    for (int k = 0; k < 4; ++k)
      filtered_max = std::max(filtered_max, double(std::abs(c.filtered[k] - gpu[i].filtered[k])));
    double dd = std::abs(c.soft[1] - gpu[i].soft[1]), ds = std::abs(c.soft[0] - gpu[i].soft[0]);
    depth_max = std::max(depth_max, dd);
    shadow_max = std::max(shadow_max, ds);
    beyond += (dd > 1e-3 || ds > 1e-3) ? 1 : 0;
    early += c.soft[3] == 0.0f ? 1 : 0;
    penumbra += (c.soft[0] > 0.02f && c.soft[0] < 0.98f) ? 1 : 0;
    lit += c.soft[0] <= 0.02f ? 1 : 0;
  }
  std::printf(
      "[sat-queries] %s: %u queries (%d ended by the search, %d in penumbrae, %d lit): rect sums differ %d, filtered "
      "max %.2e, blocker depth max %.2e, shadow max %.2e, beyond 1e-3: %d\n",
      GetParam().name, count, early, penumbra, lit, rect_mismatches, filtered_max, depth_max, shadow_max, beyond);
  EXPECT_EQ(rect_mismatches, 0);
  EXPECT_LT(filtered_max, 1e-6);
  EXPECT_LE(beyond, int(count / 500));
  EXPECT_GT(early, 100);    // umbrae (moments) or no blocker (CSSM)
  EXPECT_GT(penumbra, 500); // and the whole flow in between
}
INSTANTIATE_TEST_SUITE_P(SoftTechniques, SoftFlowOnTheDevice,
                         ::testing::Values(SoftFlowCase{"mssm4", MSM_TECH_MSSM4}, SoftFlowCase{"mssm6", MSM_TECH_MSSM6},
                                           SoftFlowCase{"vssm", MSM_TECH_VSSM}, SoftFlowCase{"cssm8", MSM_TECH_CSSM8},
                                           SoftFlowCase{"cssm16", MSM_TECH_CSSM16}),
                         [](const ::testing::TestParamInfo<SoftFlowCase>& info) { return info.param.name; });

// The renderer's shaders compose the soft-shadow flow nowhere but in soft.h: the shading calls
// msm_soft_moment_flow and msm_soft_cssm_flow, the functions the test above runs on the device, and
// no shader calls the steps that only the flow composes (the moment tables' queries, the blocker
// estimators, the umbra early-out, the receiver plane's bias, the bounds; PCSS and the hard CSM
// technique compose their own, over the depth map).
TEST(SoftFlow, TheShadersComposeItOnlyInSoftH) {
  const std::filesystem::path source(MSM_SOURCE_DIR);
  const auto read = [](const std::filesystem::path& file) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  const std::string shading = read(source / "src/render/shaders/shading_soft.glsl");
  EXPECT_NE(shading.find("msm_soft_moment_flow("), std::string::npos);
  EXPECT_NE(shading.find("msm_soft_cssm_flow("), std::string::npos);
  const char* steps[] = {"msm_sat_rect_sum",    "msm_sat_rect_average", "msm_sat_filter_average", "msm_soft_blocker",
                         "msm_soft_vssm_",      "msm_soft_shadow4",     "msm_soft_shadow6",       "msm_soft_plane_bias",
                         "msm_soft_depth_bias", "msm_soft_in_umbra",    "msm_cssm_search_terms",  "msm_cssm_blocker"};
  int files = 0;
  for (const char* dir : {"src/render/shaders", "src/gpu/shaders"})
    for (const auto& entry : std::filesystem::recursive_directory_iterator(source / dir)) {
      if (!entry.is_regular_file()) continue;
      const std::string text = read(entry.path());
      ++files;
      for (const char* step : steps)
        EXPECT_EQ(text.find(step), std::string::npos) << entry.path() << " calls " << step << " outside soft.h's flow";
    }
  EXPECT_GT(files, 50);
}

// Specialization constants are declared by name (frame.h's MSM_SPEC_*, shared.h's, the blur's,
// the prefix sums' and rectify's ids), the names the host sets them by: no shader under src/ gives
// a constant_id as a raw number, which another shader of its family could mean differently.
TEST(SharedDeclarations, SpecializationConstantIdsAreNamed) {
  const std::filesystem::path source(MSM_SOURCE_DIR);
  int declared = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(source / "src")) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".glsl" && ext != ".comp" && ext != ".frag" && ext != ".vert")) continue;
    std::ifstream in(entry.path());
    std::string line;
    while (std::getline(in, line)) {
      const std::size_t at = line.find("constant_id");
      if (at == std::string::npos) continue;
      const std::size_t value = line.find_first_not_of(" =", at + std::strlen("constant_id"));
      ++declared;
      EXPECT_TRUE(value != std::string::npos && line.compare(value, 4, "MSM_") == 0) << entry.path() << ": " << line;
    }
  }
  EXPECT_GT(declared, 15);
}

// The text of every file under `dirs` of the source tree whose extension is in `extensions`.
std::vector<std::pair<std::filesystem::path, std::string>> source_files(std::initializer_list<const char*> dirs,
                                                                        std::initializer_list<const char*> extensions) {
  const std::filesystem::path source(MSM_SOURCE_DIR);
  std::vector<std::pair<std::filesystem::path, std::string>> files;
  for (const char* dir : dirs)
    for (const auto& entry : std::filesystem::recursive_directory_iterator(source / dir)) {
      if (!entry.is_regular_file()) continue;
      const std::string ext = entry.path().extension().string();
      if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) continue;
      std::ifstream in(entry.path());
      std::stringstream text;
      text << in.rdbuf();
      files.emplace_back(std::filesystem::relative(entry.path(), source), text.str());
    }
  return files;
}

bool is_shader_side(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  return ext == ".glsl" || ext == ".comp" || ext == ".frag" || ext == ".vert" ||
         file.generic_string().find("/shaders/") != std::string::npos || file.filename() == "kernels.h";
}

// Descriptor bindings are numbered once, as MSM_BINDING_* in a header that the shader and its host
// both include (include/msm/render/bindings.h, sat_interface.h, probe_interface.h, ...): no shader
// gives a binding as a number, no host writes a positional binding list or indexes one by number,
// and every name a shader declares a binding with is one the host pushes, and the other way round.
TEST(SharedDeclarations, DescriptorBindingsAreNamed) {
  const auto files = source_files({"src", "include", "tools"}, {".glsl", ".comp", ".frag", ".vert", ".h", ".cpp"});
  const std::regex numbered_binding(R"(binding\s*=\s*[0-9])");
  const std::regex numbered_parameter(R"(#define\s+MSM_\w*BINDING\s+[0-9])"); // frame.glsl's MSM_LIGHT_BINDING...
  const std::regex declared(R"(#define\s+(MSM_BINDING_\w+)\s+[0-9]+)");
  const std::regex shader_use(R"((?:binding\s*=\s*|#define\s+MSM_\w*BINDING\s+)(MSM_BINDING_\w+))");
  const std::regex host_use(R"(MSM_BINDING_\w+)");
  const std::regex binding_type(
      R"((?:vk::)?(?:\bBinding|\bB)::(?:storage_buffer|uniform_buffer|storage_image|sampled_image))");
  const std::regex named_before(R"((?:MSM_BINDING_\w+\s*,|[=?]|[^:]:)\s*$)");
  const std::regex numbered_index(R"(\[\s*[0-9]+\s*\]\s*=\s*(?:vk::)?Descriptor\b)");
  const std::regex positional_descriptors(R"(std::vector<(?:vk::)?Descriptor>\s*\w*\s*=?\s*\{)");
  std::set<std::string> names, in_shaders, on_host;
  int shader_files = 0, host_files = 0;
  for (const auto& [file, text] : files) {
    const std::string name = file.generic_string();
    const bool header = file.extension() == ".h";
    for (std::sregex_iterator m(text.begin(), text.end(), declared), end; m != end; ++m) {
      EXPECT_TRUE(header) << name << " declares " << (*m)[1] << " outside a shared header";
      EXPECT_TRUE(names.insert((*m)[1]).second) << (*m)[1] << " declared twice";
    }
    if (is_shader_side(file)) {
      ++shader_files;
      for (std::sregex_iterator m(text.begin(), text.end(), numbered_binding), end; m != end; ++m)
        ADD_FAILURE() << name << ": a binding given as a number: " << text.substr(size_t(m->position()), 40);
      for (std::sregex_iterator m(text.begin(), text.end(), numbered_parameter), end; m != end; ++m)
        ADD_FAILURE() << name << ": a binding given as a number: " << m->str();
      for (std::sregex_iterator m(text.begin(), text.end(), shader_use), end; m != end; ++m) in_shaders.insert((*m)[1]);
      continue;
    }
    // msm::vk's own program code and its test of bindings_at's errors are the numbering's machinery.
    if (name == "src/vk/program.cpp" || name == "include/msm/vk/program.h" || name == "src/vk/vk_test.cpp") {
      for (std::sregex_iterator m(text.begin(), text.end(), host_use), end; m != end; ++m) on_host.insert(m->str());
      continue;
    }
    ++host_files;
    const std::string uses = std::regex_replace(text, declared, ""); // a declaration pushes nothing
    for (std::sregex_iterator m(uses.begin(), uses.end(), host_use), end; m != end; ++m) on_host.insert(m->str());
    for (std::sregex_iterator m(text.begin(), text.end(), binding_type), end; m != end; ++m) {
      const std::string before = text.substr(size_t(std::max<std::ptrdiff_t>(0, m->position() - 80)),
                                             size_t(std::min<std::ptrdiff_t>(80, m->position())));
      EXPECT_TRUE(std::regex_search(before, named_before))
          << name << ": " << m->str() << " in a positional list (give it as {MSM_BINDING_..., type}): ..." << before;
    }
    for (std::sregex_iterator m(text.begin(), text.end(), numbered_index), end; m != end; ++m)
      ADD_FAILURE() << name << ": a descriptor set by binding number: " << m->str();
    for (std::sregex_iterator m(text.begin(), text.end(), positional_descriptors), end; m != end; ++m)
      ADD_FAILURE() << name << ": a positional descriptor list (use vk::descriptors_at): " << m->str();
  }
  for (const std::string& n : in_shaders) {
    EXPECT_TRUE(names.count(n)) << n << ": used by a shader, declared nowhere";
    EXPECT_TRUE(on_host.count(n)) << n << ": a shader's binding that no host code pushes by this name";
  }
  for (const std::string& n : on_host)
    EXPECT_TRUE(in_shaders.count(n)) << n << ": pushed by the host, no shader declares it";
  for (const std::string& n : names) EXPECT_TRUE(in_shaders.count(n)) << n << ": declared, used by no shader";
  EXPECT_GT(shader_files, 100);
  EXPECT_GT(host_files, 100);
  EXPECT_GT(names.size(), 60u);
}

} // namespace
