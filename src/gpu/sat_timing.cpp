// GPU time of the summed-area table schemes of msm::gpu::SatBuilder against a bandwidth bound
// (docs/results.md, "Integer summed-area tables"). Not a test: prints a Markdown table.
//
//   build-soft/src/soft/msm_sat_timing [sizes...] [--repeat N]    (default sizes 1024 2048, N = 7)
//
// Per size n: an RGBA32F moment image of random Θ4* moments and an RGBA32_UINT table (16 B per
// texel each). The copy bandwidth of the device is measured by vkCmdCopyImage of the moment image
// to another RGBA32F image of the same size (reads and writes 16 B per texel). Traffic of the
// schemes, counting every texel once per pass where it is read or written (the block scheme's
// eight-fold reads are meant to hit the cache, JCGT App. C): pass 1 reads the moments and writes
// the table, pass 2 reads and writes the table: 64 B per texel. JCGT's bound (App. C) counts one
// read and one write, 32 B per texel, as a single fused pass would move. Fraction = bound / time.
// Median of N runs, each its own submission, after one warm-up.
#include "msm/gpu/sat_builder.h"
#include "msm/moments.h"
#include "msm/quantize.h"
#include "msm/vk/vk.h"

#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace msm;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

} // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes;
  int repeat = 7;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc)
      repeat = std::max(1, std::atoi(argv[++i]));
    else
      sizes.push_back(std::atoi(a.c_str()));
  }
  if (sizes.empty()) sizes = {1024, 2048};

  vk::Context ctx;
  fmt::print("device: {}\n\n", ctx.info().describe());
  gpu::SatBuilder builder(ctx);
  fmt::print("| size | copy RGBA32F (ms) | copy bandwidth (GB/s) | scheme | time (ms) | bound 64 B/texel (ms) | "
             "fraction | bound 32 B/texel (ms) | fraction |\n|---|---|---|---|---|---|---|---|---|\n");
  for (int n : sizes) {
    const uint32_t size = uint32_t(n);
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<float> depth(-1.0f, 1.0f);
    std::vector<vec4> m(size_t(size) * size);
    for (vec4& v : m) v = msm_theta4_star(msm_moments4(depth(rng)));
    vk::Image moments =
        vk::create_image(ctx, vk::ImageDesc{.width = size,
                                            .height = size,
                                            .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                            .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    vk::Image copy = vk::create_image(ctx, vk::ImageDesc{.width = size,
                                                         .height = size,
                                                         .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                                         .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    vk::Image table = vk::create_image(ctx, vk::ImageDesc{.width = size,
                                                          .height = size,
                                                          .format = VK_FORMAT_R32G32B32A32_UINT,
                                                          .usage = VK_IMAGE_USAGE_STORAGE_BIT});
    vk::upload_image(ctx, moments, std::as_bytes(std::span(m)), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    vk::GpuTimer timer(ctx);

    std::vector<double> copies;
    for (int r = 0; r <= repeat; ++r) {
      vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
        vk::pipeline_barrier(cmd, vk::image_barrier(copy.handle(), copy.aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                                    VK_ACCESS_2_MEMORY_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                                                    VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL));
        timer.reset(cmd);
        timer.begin(cmd, "copy");
        VkImageCopy region{.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                           .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                           .extent = {size, size, 1}};
        vkCmdCopyImage(cmd, moments.handle(), VK_IMAGE_LAYOUT_GENERAL, copy.handle(),
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        timer.end(cmd);
      });
      if (r > 0) copies.push_back(timer.read().total("copy"));
    }
    const double texels = double(size) * size;
    const double copy_ms = median(copies);
    const double bandwidth = 32.0 * texels / (copy_ms * 1e-3); // bytes per second
    for (auto scheme : {gpu::SatBuilder::Scheme::rows_then_columns, gpu::SatBuilder::Scheme::scan_rows_then_columns,
                        gpu::SatBuilder::Scheme::blocks}) {
      const bool blocks = scheme == gpu::SatBuilder::Scheme::blocks;
      std::vector<double> times, rows, columns;
      for (int r = 0; r <= repeat; ++r) {
        vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
          timer.reset(cmd);
          timer.begin(cmd, "sat");
          builder.record(cmd, moments, table, 27 * 27, scheme, &timer);
          timer.end(cmd);
        });
        vk::TimerResults t = timer.read();
        if (r == 0) continue;
        times.push_back(t.total("sat"));
        rows.push_back(t.total("sat_rows"));
        columns.push_back(t.total("sat_columns"));
      }
      const double ms = median(times);
      bool scan = scheme == gpu::SatBuilder::Scheme::scan_rows_then_columns;
      std::string name = blocks ? "blocks (App. C)"
                                : fmt::format("{}rows + columns ({:.2f} + {:.2f})", scan ? "scan " : "", median(rows),
                                              median(columns));
      const double bound64 = 64.0 * texels / bandwidth * 1e3, bound32 = 32.0 * texels / bandwidth * 1e3;
      fmt::print("| {}² | {:.2f} | {:.2f} | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} |\n", n, copy_ms,
                 bandwidth * 1e-9, name, ms, bound64, bound64 / ms, bound32, bound32 / ms);
    }
  }
  return 0;
}
