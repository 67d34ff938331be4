// GPU time of the summed-area table schemes of msm::gpu::SatBuilder against a bandwidth bound
// (docs/results.md, "Integer summed-area tables"). Not a test: prints a Markdown table.
//
//   build/src/gpu/msm_sat_timing [sizes...] [--repeat N]    (default sizes 1024 2048, N = 7)
//   scripts/callgrind-sat.sh [sizes...]                       (instructions per texel, --callgrind)
//
// Per size n: an RGBA32F moment image of random Θ4* moments and an RGBA32_UINT table (16 B per
// texel each). The copy bandwidth of the device is measured by vkCmdCopyImage of the moment image
// to another RGBA32F image of the same size (reads and writes 16 B per texel). Traffic of the
// schemes, counting every texel once per pass where it is read or written (the block scheme's
// eight-fold reads are meant to hit the cache, JCGT App. C): pass 1 reads the moments and writes
// the table, pass 2 reads and writes the table: 64 B per texel. JCGT's bound (App. C) counts one
// read and one write, 32 B per texel, as a single fused pass would move. Fraction = bound / time.
// Median of N runs, each its own submission, after one warm-up.
//
// The copy bound on a CPU device: a two-thread CPU copy of the same bytes (the moment
// image's 16 B per texel, two std::threads memcpy'ing one half each, best of 2N + 1 after a
// warm-up that touches both buffers): its time is the 32 B bound (one read, one write per texel),
// twice its time the 64 B bound. Every scheme's fraction of both bounds is printed beside the
// fraction of the vkCmdCopyImage bound.
//
// The copy shaders (sat_copy.h, shaders/sat_copy.glsl): shaders that only read and write
// every texel once, on RGBA32_UINT storage images (imageLoad → imageStore), on storage buffers of
// uvec4, and from the RGBA32F moment image (texelFetch → imageStore), one texel / four texels / a
// row / a column per invocation. Each is one pass moving 32 B per texel: its fraction of the 32 B
// two-thread bound is what any scheme built of such passes can reach on the device.
#include "msm/gpu/sat_builder.h"
#include "msm/moments.h"
#include "msm/quantize.h"
#include "msm/util/clock.h"
#include "msm/vk/vk.h"
#include "sat_copy.h"

#include <fmt/core.h>

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define MSM_SAT_CALLGRIND 1
#endif

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace {

using namespace msm;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Best time (ms) of `runs` copies of src into dst by two threads, one half each.
double two_thread_copy_ms(const std::vector<std::byte>& src, std::vector<std::byte>& dst, int runs) {
  const size_t half = src.size() / 2;
  auto copy = [&] {
    std::thread t([&] { std::memcpy(dst.data(), src.data(), half); });
    std::memcpy(dst.data() + half, src.data() + half, src.size() - half);
    t.join();
  };
  copy(); // warm-up: pages touched, caches in their steady state
  double best = 1e30;
  for (int r = 0; r < runs; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    copy();
    best = std::min(best, util::ms_since(t0));
  }
  return best;
}

// Callgrind labels: the schemes are 0-4 (SatBuilder::Scheme), the copy shaders 10 + their index in
// sat_copy::shaders, the two-thread CPU copy 20.
constexpr int copy_label = 10, cpu_copy_label = 20;

struct Options {
  std::vector<int> sizes;
  int repeat = 7;
  bool callgrind = false;
};

// The command line; nothing (after a message) when an argument is neither a size nor an option.
std::optional<Options> parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--callgrind")
      o.callgrind = true;
    else if (a == "--repeat" && i + 1 < argc)
      o.repeat = std::max(1, std::atoi(argv[++i]));
    else {
      int n = std::atoi(a.c_str());
      if (n < 1 || n > 16384 || a.find_first_not_of("0123456789") != std::string::npos) {
        fmt::print(stderr,
                   "msm_sat_timing: '{}' is not a size (1 to 16384) nor an option; usage: msm_sat_timing "
                   "[sizes...] [--repeat N] [--callgrind]\n",
                   a);
        return std::nullopt;
      }
      o.sizes.push_back(n);
    }
  }
  if (o.sizes.empty()) o.sizes = {1024, 2048};
#ifndef MSM_SAT_CALLGRIND
  if (o.callgrind) {
    fmt::print(stderr, "msm_sat_timing: --callgrind needs valgrind/callgrind.h at build time\n");
    return std::nullopt;
  }
#endif
  return o;
}

void print_header() {
  fmt::print("Per size: vkCmdCopyImage of the moment image and a two-thread CPU copy of its bytes (ms, GB/s at 32 B "
             "per texel). Per scheme: time (ms) and the fraction of the 64 B per texel bound (two passes) by the "
             "image copy / by the two-thread copy, and of the 32 B bound (one fused pass) by the two-thread copy. "
             "Per copy shader (one pass, 32 B per texel): time and its fraction of the 32 B bound by the "
             "two-thread copy.\n\n"
             "| size | scheme | time (ms) | rows + columns (ms) | fraction of 64 B, image copy | fraction of 64 B, "
             "2-thread copy | fraction of 32 B, 2-thread copy |\n|---|---|---|---|---|---|---|\n");
}

#ifdef MSM_SAT_CALLGRIND
// `work` under callgrind (scripts/callgrind-sat.sh): run `uncounted` times to warm the driver up,
// then once counted, in a dump labelled with the size and `label`.
template <typename Work>
void callgrind_dump(int n, int label, int uncounted, Work&& work) {
  for (int pass = 0; pass < uncounted; ++pass) work();
  CALLGRIND_START_INSTRUMENTATION;
  CALLGRIND_ZERO_STATS;
  work();
  const std::string name = fmt::format("msm-sat {} {}", n, label);
  CALLGRIND_DUMP_STATS_AT(name.c_str());
  CALLGRIND_STOP_INSTRUMENTATION;
}
#endif

// The timer's results of `repeat` submissions of `record`, after one warm-up submission.
template <typename Record>
std::vector<vk::TimerResults> timed_runs(const vk::Context& ctx, vk::GpuTimer& timer, int repeat, Record&& record) {
  std::vector<vk::TimerResults> runs;
  for (int r = 0; r <= repeat; ++r) {
    vk::submit_and_wait(ctx, record);
    vk::TimerResults t = timer.read();
    if (r > 0) runs.push_back(std::move(t));
  }
  return runs;
}

double median_ms(const std::vector<vk::TimerResults>& runs, std::string_view scope) {
  std::vector<double> times;
  for (const vk::TimerResults& t : runs) times.push_back(t.total(scope));
  return median(std::move(times));
}

// The images and timer of one size, and its bounds: the image copy's bandwidth and the
// two-thread CPU copy's time.
struct SizeRun {
  const vk::Context& ctx;
  const Options& o;
  int n;
  uint32_t size;
  std::vector<vec4> m; // random Θ4* moments
  vk::Image moments, table;
  vk::GpuTimer timer;
  double texels = 0.0, bandwidth = 0.0, cpu_ms = 0.0;

  // A storage image of the tables' format (RGBA32_UINT) and size: the table and the copy shaders' images.
  vk::Image table_image() const {
    return vk::create_image(ctx, vk::ImageDesc{.width = size,
                                               .height = size,
                                               .format = VK_FORMAT_R32G32B32A32_UINT,
                                               .usage = VK_IMAGE_USAGE_STORAGE_BIT});
  }

  SizeRun(const vk::Context& context, const Options& options, int side)
      : ctx(context), o(options), n(side), size(uint32_t(side)), m(size_t(size) * size), timer(context) {
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<float> depth(-1.0f, 1.0f);
    for (vec4& v : m) v = msm_theta4_star(msm_moments4(depth(rng)));
    moments =
        vk::create_image(ctx, vk::ImageDesc{.width = size,
                                            .height = size,
                                            .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                            .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    table = table_image();
    vk::upload_image(ctx, moments, std::as_bytes(std::span(m)), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    texels = double(size) * size;
  }

  // The bounds: vkCmdCopyImage of the moment image, and a two-thread CPU copy of its bytes.
  void measure_copies() {
    vk::Image copy = vk::create_image(ctx, vk::ImageDesc{.width = size,
                                                         .height = size,
                                                         .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                                         .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    const double copy_ms = median_ms(
        timed_runs(ctx, timer, o.repeat,
                   [&](VkCommandBuffer cmd) {
                     vk::pipeline_barrier(
                         cmd, vk::image_barrier(copy.handle(), copy.aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
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
                   }),
        "copy");
    bandwidth = 32.0 * texels / (copy_ms * 1e-3); // bytes per second
    std::vector<std::byte> src(size_t(size) * size * sizeof(vec4)), dst(src.size());
    std::memcpy(src.data(), m.data(), src.size());
    cpu_ms = two_thread_copy_ms(src, dst, 2 * o.repeat + 1);
#ifdef MSM_SAT_CALLGRIND
    // The bound's own instructions: one two-thread copy (both threads counted).
    if (o.callgrind) callgrind_dump(n, cpu_copy_label, 0, [&] { two_thread_copy_ms(src, dst, 0); });
#endif
    fmt::print("| {}² | copy: image {:.2f} ms ({:.2f} GB/s), two-thread CPU {:.2f} ms ({:.2f} GB/s) | | | | | |\n", n,
               copy_ms, bandwidth * 1e-9, cpu_ms, 32.0 * texels / (cpu_ms * 1e-3) * 1e-9);
  }

  // For comparison, not a device scheme: the same table by host code (one thread).
  void time_host_build() const {
    std::vector<double> host;
    for (int r = 0; r <= o.repeat; ++r) {
      auto t0 = std::chrono::steady_clock::now();
      std::vector<glm::uvec4> t = gpu::build_sat_cpu(m, n, n, 27 * 27);
      if (r > 0) host.push_back(util::ms_since(t0));
    }
    const double ms = median(host);
    fmt::print("| {}² | build_sat_cpu (host code, one thread; not a device scheme) | {:.2f} | | | {:.3f} | {:.3f} |\n",
               n, ms, 2.0 * cpu_ms / ms, cpu_ms / ms);
  }

  // The copy shaders: RGBA32_UINT images (the tables' format) and storage buffers of the same size.
  void time_copy_shaders(const std::vector<vk::Program>& copy_programs, const vk::Sampler& nearest) {
    vk::Image copy_src = table_image();
    vk::Image copy_dst = table_image();
    const VkDeviceSize table_bytes = VkDeviceSize(size) * size * 16;
    vk::Buffer buffer_src =
        vk::create_buffer(ctx, table_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    vk::Buffer buffer_dst = vk::create_buffer(ctx, table_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
      for (const vk::Image* image : {&copy_src, &copy_dst})
        vk::pipeline_barrier(
            cmd, vk::image_barrier(image->handle(), image->aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                   VK_ACCESS_2_MEMORY_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                   VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                   VK_IMAGE_LAYOUT_GENERAL));
      vkCmdFillBuffer(cmd, buffer_src.handle(), 0, VK_WHOLE_SIZE, 0x3f800000u);
      vk::pipeline_barrier(cmd, vk::memory_barrier(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                   VK_ACCESS_2_SHADER_STORAGE_READ_BIT));
    });
    for (int c = 0; c < gpu::sat_copy::count; ++c) {
      const gpu::sat_copy::Shader& cs = gpu::sat_copy::shaders[c];
      auto record = [&](VkCommandBuffer cmd) {
        using gpu::sat_copy::Kind;
        const vk::Descriptor src = cs.kind == Kind::buffer ? vk::Descriptor(buffer_src)
                                   : cs.kind == Kind::fetch
                                       ? vk::Descriptor(moments, VK_IMAGE_LAYOUT_GENERAL, nearest.get())
                                       : vk::Descriptor(copy_src, VK_IMAGE_LAYOUT_GENERAL);
        const vk::Descriptor dst =
            cs.kind == Kind::buffer ? vk::Descriptor(buffer_dst) : vk::Descriptor(copy_dst, VK_IMAGE_LAYOUT_GENERAL);
        gpu::sat_copy::record(cmd, copy_programs[size_t(c)], cs, size, size, src, dst);
      };
#ifdef MSM_SAT_CALLGRIND
      if (o.callgrind) {
        callgrind_dump(n, copy_label + c, 1, [&] { vk::submit_and_wait(ctx, record); });
        continue;
      }
#endif
      const double ms = median_ms(timed_runs(ctx, timer, o.repeat,
                                             [&](VkCommandBuffer cmd) {
                                               timer.reset(cmd);
                                               timer.begin(cmd, "copy");
                                               record(cmd);
                                               timer.end(cmd);
                                             }),
                                  "copy");
      // One read and one write of 16 B per texel: the 32 B bound.
      fmt::print("| {}² | copy shader: {} | {:.2f} | | | | {:.3f} |\n", n, cs.name, ms, cpu_ms / ms);
    }
  }

  // The schemes of SatBuilder, each against the bounds.
  void time_schemes(gpu::SatBuilder& builder) {
    using Scheme = gpu::SatBuilder::Scheme;
    for (auto scheme : {Scheme::rows_then_columns, Scheme::scan_rows_then_columns, Scheme::subgroup_rows_then_columns,
                        Scheme::subgroup_rows_and_columns, Scheme::blocks}) {
#ifdef MSM_SAT_CALLGRIND
      if (o.callgrind) { // the scheme alone, one submission; the script prints its instructions per texel
        callgrind_dump(n, int(scheme), 1, [&] {
          vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) { builder.record(cmd, moments, table, 27 * 27, scheme); });
        });
        continue;
      }
#endif
      const std::vector<vk::TimerResults> runs = timed_runs(ctx, timer, o.repeat, [&](VkCommandBuffer cmd) {
        timer.reset(cmd);
        timer.begin(cmd, "sat");
        builder.record(cmd, moments, table, 27 * 27, scheme, &timer);
        timer.end(cmd);
      });
      const double ms = median_ms(runs, "sat");
      const char* names[] = {"rows + columns", "blocks (App. C)", "scan rows + columns", "subgroup rows + columns",
                             "subgroup rows + subgroup columns"};
      const bool blocks = scheme == Scheme::blocks;
      std::string split =
          blocks ? "" : fmt::format("{:.2f} + {:.2f}", median_ms(runs, "sat_rows"), median_ms(runs, "sat_columns"));
      const double bound64 = 64.0 * texels / bandwidth * 1e3;
      fmt::print("| {}² | {} | {:.2f} | {} | {:.3f} | {:.3f} | {:.3f} |\n", n, names[int(builder.effective(scheme))],
                 ms, split, bound64 / ms, 2.0 * cpu_ms / ms, cpu_ms / ms);
    }
  }
};

} // namespace

int main(int argc, char** argv) {
  const std::optional<Options> o = parse_options(argc, argv);
  if (!o) return 1;
  vk::Context ctx;
  fmt::print("device: {}\n\n", ctx.info().describe());
  gpu::SatBuilder builder(ctx);
  const std::vector<vk::Program> copy_programs = gpu::sat_copy::create_programs(ctx);
  const vk::Sampler nearest = vk::create_sampler(ctx, VK_FILTER_NEAREST);
  if (!builder.subgroup_arithmetic())
    fmt::print("no subgroup arithmetic in compute shaders: the subgroup schemes run as scan rows + columns\n\n");
  print_header();
  for (int n : o->sizes) {
    SizeRun run(ctx, *o, n);
    run.measure_copies();
    if (!o->callgrind) run.time_host_build();
    run.time_copy_shaders(copy_programs, nearest);
    run.time_schemes(builder);
  }
  return 0;
}
