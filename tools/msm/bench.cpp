// `msm bench`: GPU time per pass over repeated frames (median and spread), and per technique the
// cost relative to PCF with the same kernel: shading per pixel at the given resolutions, shadow
// map (depth, resolve, blur, mips) per texel at the given sizes. JSON and a markdown table.
// `--scattering`: the scattering techniques alone (JCGT §5): the scattering pass per pixel against
// ray marching, the rectified map's passes per texel against a copy of the same bytes, timed by the
// host clock on a CPU device, whose compute timestamps are not the passes' time (docs/techniques.md).
// `--light-kinds`: the scene under one light of each kind (light_kinds.h), each kind's shadow map
// and shading against the directional light's at the same texel count.
// `--against-one-map`: cascades of each shadow size against one map of the same total texels,
// their time and their error against the ray tracer's hard shadows.
#include "light_kinds.h"
#include "probe_bench.h"
#include "render_common.h"
#include "vocabulary.h"

#include "msm/image/io.h"
#include "msm/reference/reference.h"
#include "msm/render/renderer_internals.h"
#include "msm/techniques.h"
#include "msm/util/clock.h"
#include "msm/util/statistics.h"
#include "msm/viewer/view_file.h"
#include "msm/vk/vk.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <unistd.h>

// Optional: without valgrind's header --callgrind says so (the client requests are inline asm, no-ops when
// the process does not run under valgrind).
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define MSM_HAS_CALLGRIND 1
#else
#define MSM_HAS_CALLGRIND 0
#endif

namespace msm::tool {
namespace {

struct Stats {
  double median = 0, p10 = 0, p90 = 0;
};

Stats stats(const std::vector<double>& v) { return {util::median(v), util::quantile(v, 0.1), util::quantile(v, 0.9)}; }

// Sum of the named passes per frame, then statistics over the frames.
Stats pass_sum(const std::vector<std::vector<render::PassTime>>& frames, const std::vector<std::string>& names) {
  std::vector<double> sums;
  for (const auto& frame : frames) {
    double sum = 0;
    for (const render::PassTime& p : frame)
      if (std::find(names.begin(), names.end(), p.name) != names.end()) sum += p.ms;
    sums.push_back(sum);
  }
  return stats(sums);
}

using Clock = std::chrono::steady_clock;

// The passes that make a shadow map (the cost per texel).
const std::vector<std::string> kShadowMapPasses = {"shadow_depth", "moment_resolve",  "translucent", "blur",
                                                   "mipmaps",      "one_pass_filter", "sat"};

// The copy-bandwidth bound of the prefix sums (JCGT App. C): a vkCmdCopyBuffer of `bytes`, half of
// what the prefix sums read and write per frame, so that the copy reads and writes as many bytes
// as they do. Timed three ways, median over `repeats` after one untimed round:
//  - host: the host clock around a submission with the copy, minus one without it (the submission
//    and the wait cancel);
//  - timestamps: a timer scope around the copy, as the frame's passes are timed;
//  - timestamps_flushed: the same with a pipeline barrier right after the scope's begin.
// On lavapipe only the first two agree with each other when the third does (docs/techniques.md: llvmpipe
// writes a timestamp when the binned scene it was put in is rasterized, at the next flush; a
// compute dispatch or a copy runs on the spot, before it, unless a barrier flushes it first).
struct CopyTimes {
  double host_ms = 0, timestamp_ms = 0, timestamp_flushed_ms = 0;
};
CopyTimes copy_times(const vk::Context& ctx, VkDeviceSize bytes, int repeats) {
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  vk::Buffer from = vk::create_buffer(ctx, bytes, usage), to = vk::create_buffer(ctx, bytes, usage);
  // Both written once (memory never written may cost nothing to read).
  vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, from.handle(), 0, VK_WHOLE_SIZE, 0x3f000000u);
    vkCmdFillBuffer(cmd, to.handle(), 0, VK_WHOLE_SIZE, 0u);
  });
  vk::GpuTimer timer(ctx);
  const VkMemoryBarrier2 before = vk::memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                                     VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                                     VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
  const VkMemoryBarrier2 flush =
      vk::memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0);
  const VkBufferCopy region{.srcOffset = 0, .dstOffset = 0, .size = bytes};
  auto copy = [&](VkCommandBuffer cmd) { vkCmdCopyBuffer(cmd, from.handle(), to.handle(), 1, &region); };
  std::vector<double> host, stamps, flushed;
  for (int r = -1; r < repeats; ++r) {
    Clock::time_point t0 = Clock::now();
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) { vk::pipeline_barrier(cmd, before); });
    double empty = util::ms_since(t0);
    t0 = Clock::now();
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
      vk::pipeline_barrier(cmd, before);
      copy(cmd);
    });
    double full = util::ms_since(t0);
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
      vk::pipeline_barrier(cmd, before);
      timer.reset(cmd);
      timer.begin(cmd, "copy");
      copy(cmd);
      timer.end(cmd);
    });
    double stamp = timer.read().total("copy");
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
      vk::pipeline_barrier(cmd, before);
      timer.reset(cmd);
      timer.begin(cmd, "copy");
      vk::pipeline_barrier(cmd, flush);
      copy(cmd);
      timer.end(cmd);
      vk::pipeline_barrier(cmd, flush);
    });
    if (r < 0) continue;
    host.push_back(full - empty);
    stamps.push_back(stamp);
    flushed.push_back(timer.read().total("copy"));
  }
  return {util::median(host), util::median(stamps), util::median(flushed)};
}

// Host-clock time of the named passes of a frame: pass k (frame_passes order) costs the difference
// of the frame's prefixes of k + 1 and k passes, each submitted and waited for (the submission and
// the wait cancel; whatever a driver defers within the pass is counted in it). The prefixes of a
// repeat run back to back; median over `repeats` after one untimed round. Names the frame lacks
// are left out.
std::map<std::string, double> host_pass_ms(render::Renderer& renderer, const render::RenderSettings& s,
                                           const std::vector<std::string>& names, int repeats) {
  std::vector<std::string> passes = renderer.frame_passes(s);
  std::map<std::string, size_t> index;
  std::vector<size_t> counts;
  for (const std::string& name : names)
    if (auto it = std::find(passes.begin(), passes.end(), name); it != passes.end()) {
      size_t k = size_t(it - passes.begin());
      index[name] = k;
      counts.push_back(k);
      counts.push_back(k + 1);
    }
  std::sort(counts.begin(), counts.end());
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  std::map<std::string, std::vector<double>> differences;
  for (int r = -1; r < repeats; ++r) {
    std::map<size_t, double> ms;
    for (size_t k : counts) {
      Clock::time_point t0 = Clock::now();
      render::RendererInternals::submit_frame_prefix(renderer, s, k);
      ms[k] = util::ms_since(t0);
    }
    if (r >= 0)
      for (const auto& [name, k] : index) differences[name].push_back(ms[k + 1] - ms[k]);
  }
  std::map<std::string, double> out;
  for (const auto& [name, v] : differences) out[name] = util::median(v);
  return out;
}

std::pair<int, int> parse_resolution(const std::string& text) {
  int w = 0, h = 0;
  if (std::sscanf(text.c_str(), "%dx%d", &w, &h) != 2) throw UsageError(fmt::format("resolution '{}': use WxH", text));
  return {w, h};
}

// Instruction counts must not depend on when the machine is busy: every prefix of the frame (its
// first k passes, k = 0 .. n) is submitted alone and waited for, and callgrind dumps what it
// counted in between, labelled "msm-prefix <technique> <WxH> <shadow size> <k> <pass k or ->". Pass k
// costs the difference of prefixes k and k - 1: both include the same submission, so it cancels.
// Each prefix runs once uninstrumented first, so that the driver's lazy work (shader variants)
// is not counted.
void callgrind_prefixes(render::Renderer& renderer, const FrameOptions& frame, const std::vector<std::string>& names,
                        std::pair<int, int> resolution, const std::vector<int>& shadow_sizes, int warmup) {
#if MSM_HAS_CALLGRIND
  for (const std::string& name : names)
    for (int size : shadow_sizes) {
      render::RenderSettings s = settings_for(frame, name);
      s.width = resolution.first;
      s.height = resolution.second;
      s.shadow_size = size;
      renderer.time_frames(s, std::max(warmup, 1));
      std::vector<std::string> passes = renderer.frame_passes(s);
      for (int instrumented = 0; instrumented < 2; ++instrumented) {
        if (instrumented) CALLGRIND_START_INSTRUMENTATION;
        for (size_t k = 0; k <= passes.size(); ++k) {
          CALLGRIND_ZERO_STATS;
          render::RendererInternals::submit_frame_prefix(renderer, s, k);
          if (instrumented) {
            std::string label =
                fmt::format("msm-prefix {} {}x{} {} {} {}", name, s.width, s.height, size, k, k ? passes[k - 1] : "-");
            CALLGRIND_DUMP_STATS_AT(label.c_str());
          }
        }
        if (instrumented) CALLGRIND_STOP_INSTRUMENTATION;
      }
      fmt::print("{} {}x{} {}: {} prefixes dumped\n", name, s.width, s.height, size, passes.size() + 1);
    }
#else
  (void)renderer, (void)frame, (void)names, (void)resolution, (void)shadow_sizes, (void)warmup;
#endif
}

// Before the device opens: --callgrind counts nothing outside callgrind.
void check_callgrind() {
#if MSM_HAS_CALLGRIND
  if (!RUNNING_ON_VALGRIND)
    throw UsageError("--callgrind: run under valgrind --tool=callgrind --instr-atstart=no "
                     "(scripts/callgrind-passes.sh does)");
#else
  throw UsageError("--callgrind: this msm was built without valgrind/callgrind.h (apt-get install valgrind)");
#endif
}

// The scattering part of the markdown, and the ratios it adds to the JSON: the scattering pass per
// pixel against ray marching in the same run; the same with the rectified map's passes at the
// frames' shadow size; the rectified map per texel with the prefix sums against the copy; the
// timestamps of the passes against the host clock.
std::string scattering_markdown(nlohmann::json& results, const std::vector<std::pair<int, int>>& resolutions,
                                int shadow_size, const std::string& clock) {
  std::string md;
  auto find = [&](const std::string& technique) -> const nlohmann::json* {
    for (const nlohmann::json& e : results)
      if (e["technique"] == technique && e.contains("scattering")) return &e;
    return nullptr;
  };
  auto header = [&](const std::string& title) {
    std::string h = "\n" + title + "\n\n| technique |";
    for (auto [w, h2] : resolutions) h += fmt::format(" {}x{} |", w, h2);
    h += "\n|---|";
    for (size_t i = 0; i < resolutions.size(); ++i) h += "---:|";
    return h + "\n";
  };
  bool any = false, with_maps = false, rectified = false;
  const std::string map = std::to_string(shadow_size);
  for (const nlohmann::json& e : results) {
    any = any || e.contains("scattering");
    rectified = rectified || e.contains("rectified");
    with_maps = with_maps || (e.contains("rectified") && e["rectified"].contains(map));
  }
  if (!any) return md;
  const nlohmann::json* march128 = find("scatter-march-128");
  md += header("Single scattering, the scattering pass alone (timestamps): ms (ns per pixel; × scatter-march-128; "
               "× scatter-march-32, where they ran)");
  for (nlohmann::json& entry : results) {
    if (!entry.contains("scattering")) continue;
    md += fmt::format("| {} |", entry["technique"].get<std::string>());
    for (auto [w, h] : resolutions) {
      std::string key = fmt::format("{}x{}", w, h);
      nlohmann::json& v = entry["scattering"][key];
      double ns = v["ns_per_pixel"].get<double>();
      md += fmt::format(" {:.3f} ({:.1f}", v["median_ms"].get<double>(), ns);
      for (const char* march : {"scatter-march-128", "scatter-march-32"})
        if (const nlohmann::json* m = find(march)) {
          double ratio = ns / (*m)["scattering"][key]["ns_per_pixel"].get<double>();
          v[std::string("ratio_to_") + march] = ratio;
          md += fmt::format("; {:.3f}", ratio);
        }
      md += ") |";
    }
    md += "\n";
  }
  if (with_maps) {
    md += header(fmt::format("With the rectified map: the scattering pass + rectify + prefix sums at {}² ({}), ms "
                             "(× scatter-march-128's scattering pass)",
                             shadow_size, clock));
    for (nlohmann::json& entry : results) {
      if (!entry.contains("scattering")) continue;
      md += fmt::format("| {} |", entry["technique"].get<std::string>());
      const bool prefiltered =
          render::find_rendered_technique(entry["technique"].get<std::string>()).prefiltered_scattering();
      for (auto [w, h] : resolutions) {
        std::string key = fmt::format("{}x{}", w, h);
        nlohmann::json& v = entry["scattering"][key];
        if (prefiltered && !(entry.contains("rectified") && entry["rectified"].contains(map))) {
          md += " – |";
          continue;
        }
        double ms = v["median_ms"].get<double>();
        if (prefiltered)
          ms += entry["rectified"][map]["rectify_ms"].get<double>() +
                entry["rectified"][map]["prefix_sums_ms"].get<double>();
        v["with_rectified_map_ms"] = ms;
        md += fmt::format(" {:.3f}", ms);
        if (march128) {
          double ratio = ms / (*march128)["scattering"][key]["median_ms"].get<double>();
          v["with_rectified_map_ratio_to_scatter-march-128"] = ratio;
          md += fmt::format(" ({:.3f})", ratio);
        }
        md += " |";
      }
      md += "\n";
    }
  }
  if (rectified) {
    md += fmt::format(
        "\nThe rectified map per texel ({}), the prefix sums against a copy of the bytes they read and "
        "write, for the frame's scheme and then\nfor each scheme (rows: a thread per row; App. C: JCGT's Appendix "
        "C)\n\n| "
        "technique | map | rectify ms (ns per texel) | prefix sums ms (ns per texel) | copy ms "
        "(GB/s) | copy / prefix sums | rows ms (copy / rows) | App. C ms (copy / App. C) | timestamps: "
        "rectify, prefix sums, copy, copy after a barrier (ms) |\n|---|---|---:|---:|---:|---:|---:|---:|---|"
        "\n",
        clock);
    std::string check;
    for (const nlohmann::json& entry : results) {
      if (!entry.contains("rectified")) continue;
      const std::string name = entry["technique"].get<std::string>();
      std::vector<int> sizes; // in numeric order (the JSON object's keys sort as text)
      for (const auto& [key, value] : entry["rectified"].items()) sizes.push_back(std::stoi(key));
      std::sort(sizes.begin(), sizes.end());
      for (int size : sizes) {
        const nlohmann::json &v = entry["rectified"][std::to_string(size)], &t = v["timestamps"], &hc = v["host_clock"];
        md += fmt::format(
            "| {} | {}² | {:.3f} ({:.1f}) | {:.3f} ({:.1f}) | {:.3f} ({:.1f}) | {:.3f} | {:.3f} ({:.3f}) | {:.3f} "
            "({:.3f}) | {:.3f}, {:.3f}, {:.3f}, {:.3f} |\n",
            name, size, v["rectify_ms"].get<double>(), v["rectify_ns_per_texel"].get<double>(),
            v["prefix_sums_ms"].get<double>(), v["prefix_sums_ns_per_texel"].get<double>(), v["copy_ms"].get<double>(),
            v["copy_gb_s"].get<double>(), v["fraction_of_bound"].get<double>(), v["schemes"]["rows_ms"].get<double>(),
            v["schemes"]["rows_fraction_of_bound"].get<double>(), v["schemes"]["appendix_c_ms"].get<double>(),
            v["schemes"]["appendix_c_fraction_of_bound"].get<double>(), t["rectify_ms"].get<double>(),
            t["prefix_sums_ms"].get<double>(), t["copy_ms"].get<double>(), t["copy_after_barrier_ms"].get<double>());
        check += fmt::format(" {} {}²: {:.3f} / {:.3f};", name, size, t["scattering_320x180_ms"].get<double>(),
                             hc["scattering_320x180_ms"].get<double>());
      }
    }
    md += "\nThe scattering pass at 320x180, timestamps / host clock (ms):" + check + "\n";
  }
  return md;
}

} // namespace

struct BenchOptions {
  FrameOptions frame;
  std::vector<std::string> techniques;
  std::vector<std::string> resolutions = {"1920x1080", "3840x2160"};
  std::vector<int> shadow_sizes = {1024, 2048};
  int frames = 20, warmup = 2, repeats = 5;
  std::string json, markdown;
  bool callgrind = false, scattering = false, quick = false, light_kinds = false;
  bool against_one_map = false; // cascades against one map of the same total texels
  ProbeBench probe;
};

void add_bench_options(CLI::App* cmd, BenchOptions& o) {
  add_term(cmd, "--techniques", o.techniques, " (default: all)")->delimiter(',');
  cmd->add_option("--resolutions", o.resolutions, "Image sizes for the shading cost")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--shadow-sizes", o.shadow_sizes, "Shadow map sizes for the shadow-map cost")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--frames", o.frames, "Timed frames per configuration")->capture_default_str();
  cmd->add_option("--warmup", o.warmup, "Untimed frames first")->capture_default_str();
  cmd->add_option("--repeats", o.repeats,
                  "Host-clock repeats (median) of the frame prefixes and of the copy that time the rectified map's "
                  "passes")
      ->capture_default_str();
  cmd->add_flag("--scattering", o.scattering,
                "Single scattering (JCGT §5): the scattering pass per pixel against ray marching, the rectified "
                "map's passes per texel against a copy of the same bytes; unless given: techniques "
                "scatter-march-32,scatter-march-128,scatter-msm4-64,scatter-msm6-96,scatter-csm-32, scene tower, "
                "shadow sizes 512,1024,2048; no PCF table");
  cmd->add_flag("--light-kinds", o.light_kinds,
                "Per-light shadow cost of each light kind: the scene under one directional, spot and point light in "
                "turn (placed on the scene's light direction; kinds the renderer does not draw are skipped with its "
                "message), each kind's shadow map and shading against the directional light's at the same texel "
                "count (a point light's six faces against six maps); unless given: techniques "
                "pcf,vsm-32,msm-hamburger-64");
  cmd->add_flag("--against-one-map", o.against_one_map,
                "Cascaded shadow maps against one map of the same total texels: --cascades (default 4) cascades of "
                "each shadow size against one map of size x sqrt(count), the shadow-map passes' and the frame's time "
                "at the first resolution and the error against the ray tracer's hard shadows there (e.g. --scene "
                "scenes/box_on_ground.json or scenes/town.json); unless given: techniques pcf,msm-hamburger-64");
  cmd->add_flag("--quick", o.quick,
                "A short run, to check that it works (not for recorded numbers): unless given, resolution 320x180, "
                "shadow size and sizes 256, 1 frame after 1 warm-up, 2 repeats");
  cmd->add_option("--json-file", o.json, "Write the results as JSON here");
  add_deprecated_option(cmd, "--json", "--json-file", o.json);
  cmd->add_option("--markdown", o.markdown, "Write the results as a markdown table here");
  cmd->add_flag("--callgrind", o.callgrind,
                "Under valgrind --tool=callgrind --instr-atstart=no: one callgrind dump per prefix of each frame "
                "(first resolution, each shadow size) instead of times; scripts/callgrind-passes.sh turns them into "
                "instructions per pass");
  add_term(cmd, "--probe", o.probe.probe,
           ": time the light-probe pipeline instead: cube map, tables and median cut on the device against face "
           "size and light count");
  cmd->add_option("--probe-sizes", o.probe.sizes, "Face sizes for --probe")->delimiter(',')->capture_default_str();
  add_deprecated_option(cmd, "--probe-lights", "--lights", o.probe.lights)->delimiter(',');
  add_term(cmd, "--lights", o.probe.lights, ": the counts timed with --probe")->delimiter(',')->capture_default_str();
  add_frame_options(cmd, o.frame);
}

// --quick and --scattering: their defaults of what is not given.
void apply_bench_defaults(BenchOptions& o, const CLI::App& cmd) {
  auto given = [&cmd](const char* option) { return cmd.get_option(option)->count() > 0; };
  if (o.quick) {
    if (!given("--resolutions")) o.resolutions = {"320x180"};
    if (!given("--shadow-sizes")) o.shadow_sizes = {256};
    if (!given("--shadow-size")) o.frame.settings.shadow_size = 256;
    if (!given("--frames")) o.frames = 1;
    if (!given("--warmup")) o.warmup = 1; // lavapipe compiles shader variants in a configuration's first frame
    if (!given("--repeats")) o.repeats = 2;
  }
  if (o.light_kinds) {
    if (o.scattering || !o.probe.probe.empty())
      throw UsageError("--light-kinds, --scattering and --probe: one at a time");
    if (o.techniques.empty()) o.techniques = {"pcf", "vsm-32", "msm-hamburger-64"};
  }
  if (o.against_one_map) {
    if (o.light_kinds || o.scattering || !o.probe.probe.empty())
      throw UsageError("--against-one-map, --light-kinds, --scattering and --probe: one at a time");
    if (o.frame.settings.cascades.value_or(render::kDefaultCascades) < 2)
      throw UsageError("--against-one-map: --cascades must be at least 2");
    if (o.techniques.empty()) o.techniques = {"pcf", "msm-hamburger-64"};
  }
  if (o.scattering) {
    if (!o.probe.probe.empty()) throw UsageError("--scattering and --probe: one at a time");
    if (!given("--scene")) o.frame.scene = "tower";
    if (!given("--shadow-sizes") && !o.quick) o.shadow_sizes = {512, 1024, 2048};
    if (o.techniques.empty())
      o.techniques = {"scatter-march-32", "scatter-march-128", "scatter-msm4-64", "scatter-msm6-96", "scatter-csm-32"};
  }
}

// The rectified map and its prefix sums of a prefiltered scattering technique at one shadow-map
// size: per texel, against a copy of the bytes they read and write, both schemes of the sums.
nlohmann::json rectified_json(render::Renderer& renderer, const vk::Context& ctx, const BenchOptions& o,
                              const render::RenderSettings& s, const std::vector<std::vector<render::PassTime>>& frames,
                              const Technique& technique, int size, bool host_clock) {
  auto run = [&](const render::RenderSettings& settings) {
    if (o.warmup) renderer.time_frames(settings, o.warmup);
    return renderer.time_frames(settings, o.frames);
  };
  // The rectified map and its prefix sums per texel, and the prefix sums against a copy of
  // the bytes they read and write, both by the host clock on a CPU device. The scattering
  // pass (320x180) both ways too: a check of the timestamps the per-pixel table uses.
  Stats rect = pass_sum(frames, {"rectify"}), prefix = pass_sum(frames, {"prefix_sums"}),
        scatter = pass_sum(frames, {"scattering"});
  std::map<std::string, double> host = host_pass_ms(renderer, s, {"rectify", "prefix_sums", "scattering"}, o.repeats);
  const glm::ivec2 bytes = msm_technique_scatter_map_bytes(technique.id);
  const double texels = double(size) * size;
  // The prefix sums read the rectified map and write their layer once per transmittance layer.
  const auto copy_bytes = VkDeviceSize(texels * (bytes.x + bytes.y) / 2 * render::transmittance_layers(s));
  CopyTimes copy = copy_times(ctx, copy_bytes, o.repeats);
  const double rect_ms = host_clock ? host["rectify"] : rect.median,
               prefix_ms = host_clock ? host["prefix_sums"] : prefix.median,
               copy_ms = host_clock ? copy.host_ms : copy.timestamp_ms;
  // The other scheme of the prefix sums (RenderSettings::prefix_sums), by the same clock.
  render::RenderSettings other = s;
  other.prefix_sums = s.prefix_sums == render::RenderSettings::PrefixSums::rows
                          ? render::RenderSettings::PrefixSums::appendix_c
                          : render::RenderSettings::PrefixSums::rows;
  const double other_ms = host_clock ? host_pass_ms(renderer, other, {"prefix_sums"}, o.repeats)["prefix_sums"]
                                     : pass_sum(run(other), {"prefix_sums"}).median;
  const bool rows = s.prefix_sums == render::RenderSettings::PrefixSums::rows;
  const double rows_ms = rows ? prefix_ms : other_ms, appendix_c_ms = rows ? other_ms : prefix_ms;
  return {{"clock", host_clock ? "host" : "timestamps"},
          {"rectify_ms", rect_ms},
          {"prefix_sums_ms", prefix_ms},
          {"rectify_ns_per_texel", rect_ms * 1e6 / texels},
          {"prefix_sums_ns_per_texel", prefix_ms * 1e6 / texels},
          {"bytes_read_per_texel", bytes.x},
          {"bytes_written_per_texel", bytes.y},
          {"copy_ms", copy_ms},
          {"copy_gb_s", 2.0 * double(copy_bytes) / (copy_ms * 1e6)},
          {"fraction_of_bound", copy_ms / prefix_ms},
          {"schemes",
           {{"rows_ms", rows_ms},
            {"appendix_c_ms", appendix_c_ms},
            {"rows_fraction_of_bound", copy_ms / rows_ms},
            {"appendix_c_fraction_of_bound", copy_ms / appendix_c_ms}}},
          {"host_clock",
           {{"rectify_ms", host["rectify"]},
            {"prefix_sums_ms", host["prefix_sums"]},
            {"scattering_320x180_ms", host["scattering"]},
            {"copy_ms", copy.host_ms}}},
          {"timestamps",
           {{"rectify_ms", rect.median},
            {"prefix_sums_ms", prefix.median},
            {"scattering_320x180_ms", scatter.median},
            {"copy_ms", copy.timestamp_ms},
            {"copy_after_barrier_ms", copy.timestamp_flushed_ms}}}};
}

// Each technique's cost relative to PCF where it ran, the soft techniques' shading also to PCSS
// where it ran (JCGT §4: two table queries against hundreds of taps).
void add_ratios(nlohmann::json& results, std::map<std::string, std::map<std::string, double>>& per_unit) {
  bool with_pcf = per_unit.count("pcf") > 0, with_pcss = per_unit.count("pcss") > 0;
  for (nlohmann::json& entry : results) {
    const std::string name = entry["technique"];
    for (auto& [key, value] : entry["shading"].items()) {
      if (with_pcf) value["ratio_to_pcf"] = per_unit[name]["shading " + key] / per_unit["pcf"]["shading " + key];
      if (with_pcss && render::find_rendered_technique(name).area_light)
        value["ratio_to_pcss"] = per_unit[name]["shading " + key] / per_unit["pcss"]["shading " + key];
    }
    if (with_pcf)
      for (auto& [key, value] : entry["shadow_map"].items())
        value["ratio_to_pcf"] = per_unit[name]["shadow " + key] / per_unit["pcf"]["shadow " + key];
  }
}

// The markdown table of the results (and the scattering part where they have one, which adds its
// ratios to the results).
std::string bench_markdown(const BenchOptions& o, const vk::Context& ctx, const scene::Scene& scene,
                           nlohmann::json& results, const std::vector<std::pair<int, int>>& resolutions,
                           bool host_clock) {
  bool with_pcf = false, with_pcss = false; // where they ran
  for (const nlohmann::json& entry : results) {
    with_pcf = with_pcf || entry["technique"] == "pcf";
    with_pcss = with_pcss || entry["technique"] == "pcss";
  }
  std::string md =
      fmt::format("Device: {}. Scene '{}', {} frames per configuration (median; p10–p90 in JSON), "
                  "{}x MSAA, {}² Gaussian.\n",
                  ctx.info().describe(), scene.name, o.frames, o.frame.settings.msaa, o.frame.settings.filter_size);
  if (with_pcf) {
    md += "\n| technique |";
    for (auto [w, h] : resolutions) md += fmt::format(" shading {}x{} ms (× PCF) |", w, h);
    for (int size : o.shadow_sizes) md += fmt::format(" shadow map {}² ms (× PCF) |", size);
    md += "\n|---|";
    for (size_t i = 0; i < resolutions.size() + o.shadow_sizes.size(); ++i) md += "---:|";
    md += "\n";
    for (const nlohmann::json& entry : results) {
      md += fmt::format("| {} |", entry["technique"].get<std::string>());
      for (auto [w, h] : resolutions) {
        const auto& v = entry["shading"][fmt::format("{}x{}", w, h)];
        md += fmt::format(" {:.3f} ({:.2f}) |", v["median_ms"].get<double>(), v["ratio_to_pcf"].get<double>());
      }
      for (int size : o.shadow_sizes) {
        const auto& v = entry["shadow_map"][std::to_string(size)];
        md += fmt::format(" {:.3f} ({:.2f}) |", v["median_ms"].get<double>(), v["ratio_to_pcf"].get<double>());
      }
      md += "\n";
    }
  }
  if (with_pcss) {
    md += fmt::format("\nSoft shadows, shading time relative to pcss ({}² search):",
                      o.frame.settings.soft_kernel ? o.frame.settings.soft_kernel : render::kDefaultPcssKernel);
    for (const nlohmann::json& entry : results)
      for (auto [w, h] : resolutions) {
        const auto& v = entry["shading"][fmt::format("{}x{}", w, h)];
        if (v.contains("ratio_to_pcss") && entry["technique"] != "pcss")
          md += fmt::format(" {} {}x{}: {:.3f};", entry["technique"].get<std::string>(), w, h,
                            v["ratio_to_pcss"].get<double>());
      }
    md += "\n";
  }
  md += scattering_markdown(results, resolutions, o.frame.settings.shadow_size,
                            host_clock ? fmt::format("host clock, median of {} repeats", o.repeats)
                                       : fmt::format("timestamps, median of {} frames", o.frames));
  return md;
}

// The cascades' depth bounds (pre-pass + reduction, the pass "depth_bounds") against the frame,
// where a configuration measured them; empty where none did.
std::string depth_bounds_markdown(const nlohmann::json& results) {
  std::string md;
  for (const nlohmann::json& entry : results)
    if (entry.contains("depth_bounds"))
      for (const auto& [resolution, v] : entry["depth_bounds"].items())
        md += fmt::format("| {} | {} | {:.3f} | {:.3f} | {:.1f}% |\n", entry["technique"].get<std::string>(),
                          resolution, v["median_ms"].get<double>(), v["frame_ms"].get<double>(),
                          100.0 * v["share_of_frame"].get<double>());
  if (md.empty()) return md;
  return "\nCascades' depth bounds (camera depth pre-pass + min/max reduction, read back before the frame):\n\n"
         "| technique | resolution | depth bounds ms | frame ms | share of the frame |\n|---|---|---:|---:|---:|\n" +
         md;
}

// A progress line: rewritten in place on a terminal, one line per step in a log.
void print_progress(bool tty, const std::string& line) {
  if (tty)
    fmt::print(stderr, "\r{:<70}", line);
  else
    fmt::print(stderr, "{}\n", line);
}

// The techniques to time, canonical names (default: all; --scattering: only scattering ones), PCF
// first unless under callgrind or --scattering (the ratios' reference).
std::vector<std::string> bench_techniques(const BenchOptions& o) {
  std::vector<std::string> names = canonical_technique_names(o.techniques);
  if (names.empty())
    for (const Technique* t : render::rendered_techniques()) names.emplace_back(t->name);
  if (o.scattering)
    for (const std::string& name : names)
      if (!render::find_rendered_technique(name).scatters())
        throw UsageError(fmt::format("--scattering: '{}' is not a scattering technique (msm techniques)", name));
  if (!o.callgrind && !o.scattering && std::find(names.begin(), names.end(), "pcf") == names.end())
    names.insert(names.begin(), "pcf");
  return names;
}

// Every configuration is valid before the first frame: UsageError naming the first problem.
void validate_configurations(const BenchOptions& o, const std::vector<std::string>& names,
                             const std::vector<std::pair<int, int>>& resolutions) {
  // Validate every configuration before the first frame.
  for (const std::string& name : names) {
    render::RenderSettings s = settings_for(o.frame, name);
    try {
      for (auto [w, h] : resolutions) {
        s.width = w;
        s.height = h;
        s.validate();
      }
      for (int size : o.shadow_sizes) {
        s.shadow_size = size;
        s.validate();
      }
    } catch (const render::RenderError& e) { throw UsageError(e.what()); }
  }
}

// --json and --markdown, each written whole or not at all.
void write_results(const BenchOptions& o, const nlohmann::json& doc, const std::string& md) {
  auto write = [](const std::string& path, const std::string& text) {
    try {
      image::write_file_atomic(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    } catch (const image::ImageError& e) { throw UsageError(e.what()); }
  };
  if (!o.json.empty()) write(o.json, doc.dump(2) + "\n");
  if (!o.markdown.empty()) write(o.markdown, md);
}

namespace {
// --frames, --warmup and --repeats within their ranges; UsageError otherwise.
void check_frame_counts(const BenchOptions& o) {
  if (o.frames < 1 || o.frames > 10000) throw UsageError("--frames must be in [1, 10000]");
  if (o.warmup < 0 || o.warmup > 1000) throw UsageError("--warmup must be in [0, 1000]");
  if (o.repeats < 1 || o.repeats > 1000) throw UsageError("--repeats must be in [1, 1000]");
}
} // namespace

// --light-kinds: each technique's shadow map (per size) and shading (per resolution) with the scene
// under one light of each kind the renderer draws, and its ratio to the directional light's at the
// same texel count: a kind's shadow_views maps against as many directional maps. Kinds and
// techniques the renderer refuses are listed with its message.
void bench_light_kinds(const BenchOptions& o, const std::vector<std::string>& names,
                       const std::vector<std::pair<int, int>>& resolutions) {
  const scene::Scene base = scene_at_frame(o.frame, load_scene_or_fail(o.frame.scene));
  std::vector<std::pair<const scene::LightKindInfo*, scene::Scene>> kinds;
  for (const scene::LightKindInfo& kind : scene::light_kinds())
    kinds.emplace_back(&kind, scene_under_light_kind(base, kind.kind));
  std::unique_ptr<vk::Context> ctx = open_device(o.frame.device);
  auto run = [&](render::Renderer& renderer, const render::RenderSettings& s) {
    if (o.warmup) renderer.time_frames(s, o.warmup);
    return renderer.time_frames(s, o.frames);
  };
  nlohmann::json results = nlohmann::json::array(), skipped = nlohmann::json::array();
  std::map<std::string, double> directional_ms; // "technique shadow SIZE" / "technique shading WxH"
  std::string md = fmt::format("Device: {}. Scene '{}' under one light of each kind, {} frames per configuration "
                               "(median), {}x MSAA; × directional: against the directional light's time for as many "
                               "texels (a kind's maps per light × one directional map) or pixels.\n\n| kind | "
                               "technique |",
                               ctx->info().describe(), base.name, o.frames, o.frame.settings.msaa);
  for (int size : o.shadow_sizes) md += fmt::format(" shadow map {}² ms (× directional) |", size);
  for (auto [w, h] : resolutions) md += fmt::format(" shading {}x{} ms (× directional) |", w, h);
  md += "\n|---|---|";
  for (size_t i = 0; i < o.shadow_sizes.size() + resolutions.size(); ++i) md += "---:|";
  md += "\n";
  for (auto& [kind, scene] : kinds) {
    std::optional<render::Renderer> renderer;
    try {
      renderer.emplace(*ctx, scene);
    } catch (const render::RenderError& e) {
      fmt::print(stderr, "msm bench: {} light skipped: {}\n", kind->name, e.what());
      skipped.push_back({{"kind", kind->name}, {"reason", e.what()}});
      continue;
    }
    for (const std::string& name : names) {
      nlohmann::json entry = {{"kind", kind->name},
                              {"shadow_views", kind->shadow_views},
                              {"technique", name},
                              {"shadow_map", nlohmann::json::object()},
                              {"shading", nlohmann::json::object()}};
      std::string row = fmt::format("| {} | {} |", kind->name, name);
      auto add = [&](const std::string& part, const std::string& key, const Stats& st, double units) {
        const std::string id = name + " " + part + " " + key;
        if (kind->kind == scene::LightKind::directional) directional_ms[id] = st.median;
        nlohmann::json v = {{"median_ms", st.median}, {"p10_ms", st.p10}, {"p90_ms", st.p90}};
        v[part == "shadow_map" ? "ns_per_texel" : "ns_per_pixel"] = st.median * 1e6 / units;
        row += fmt::format(" {:.3f}", st.median);
        if (directional_ms.count(id)) {
          const double views = part == "shadow_map" ? kind->shadow_views : 1;
          v["ratio_to_directional"] = st.median / (views * directional_ms[id]);
          row += fmt::format(" ({:.2f})", v["ratio_to_directional"].get<double>());
        }
        row += " |";
        entry[part][key] = v;
      };
      try {
        for (int size : o.shadow_sizes) {
          render::RenderSettings s = settings_for(o.frame, name);
          s.width = 320; // the shadow-map passes do not depend on the image size
          s.height = 180;
          s.shadow_size = size;
          add("shadow_map", std::to_string(size), pass_sum(run(*renderer, s), kShadowMapPasses),
              double(kind->shadow_views) * size * size);
        }
        for (auto [w, h] : resolutions) {
          render::RenderSettings s = settings_for(o.frame, name);
          s.width = w;
          s.height = h;
          add("shading", fmt::format("{}x{}", w, h), pass_sum(run(*renderer, s), {"surfaces", "shading"}),
              double(w) * h);
        }
      } catch (const render::RenderError& e) {
        fmt::print(stderr, "msm bench: {} with a {} light skipped: {}\n", name, kind->name, e.what());
        skipped.push_back({{"kind", kind->name}, {"technique", name}, {"reason", e.what()}});
        continue;
      }
      results.push_back(entry);
      md += row + "\n";
    }
  }
  fmt::print("{}", md);
  const nlohmann::json doc = {{"device", ctx->info().describe()},
                              {"scene", base.name},
                              {"frames", o.frames},
                              {"warmup", o.warmup},
                              {"msaa", o.frame.settings.msaa},
                              {"filter_size", o.frame.settings.filter_size},
                              {"light_kinds", results},
                              {"skipped", skipped}};
  write_results(o, doc, md);
}

// The mean absolute error of the shadow buffer against the ray tracer's visibility over the pixels
// that show a surface, and the error summed per pixel the tracer shadows (visibility below 1/2:
// comparable between a scene of large shadows and one of a small shadow on a large lit ground).
std::pair<double, double> error_against(const render::RenderResult& r, const reference::Result& truth) {
  double sum = 0.0;
  std::size_t surface = 0, shadowed = 0;
  for (int y = 0; y < truth.visibility.height(); ++y)
    for (int x = 0; x < truth.visibility.width(); ++x) {
      if (truth.visibility.at(x, y, 1) > 0.5f) continue; // background
      const float v = truth.visibility.at(x, y, 0);
      sum += std::abs(double(r.shadow.at(x, y, 0)) - double(v));
      ++surface;
      shadowed += v < 0.5f;
    }
  return {sum / double(std::max<std::size_t>(surface, 1)), sum / double(std::max<std::size_t>(shadowed, 1))};
}

// --against-one-map: per technique and shadow size S, N cascades (--cascades, default 4) of S²
// against one map of (S sqrt(N))²
// (the same texels): the shadow-map passes' and the whole frame's time at the first resolution,
// and the error against the ray tracer's hard shadows there.
void bench_cascades(const BenchOptions& o, const std::vector<std::string>& names,
                    const std::vector<std::pair<int, int>>& resolutions) {
  const scene::Scene scene = scene_at_frame(o.frame, load_scene_or_fail(o.frame.scene));
  std::unique_ptr<vk::Context> ctx = open_device(o.frame.device);
  render::Renderer renderer(*ctx, scene);
  const auto [width, height] = resolutions.front();
  const int cascades = o.frame.settings.cascades.value_or(render::kDefaultCascades);
  reference::Settings traced;
  traced.width = width;
  traced.height = height;
  const reference::Result truth = reference::render(scene, traced);
  nlohmann::json results = nlohmann::json::array();
  std::string md = fmt::format("Device: {}. Scene '{}', {}x{}, {} frames per configuration (median), {}x MSAA; "
                               "error against the ray tracer's hard shadows (MAE over the surface; summed per "
                               "pixel the tracer shadows).\n\n| technique | maps | shadow-map passes ms | frame ms | "
                               "MAE | error per shadowed pixel |\n|---|---|---:|---:|---:|---:|\n",
                               ctx->info().describe(), scene.name, width, height, o.frames, o.frame.settings.msaa);
  for (const std::string& name : names)
    for (int size : o.shadow_sizes)
      for (int count : {cascades, 1}) {
        render::RenderSettings s = settings_for(o.frame, name);
        s.width = width;
        s.height = height;
        s.cascades = count;
        s.shadow_size = count == 1 ? int(std::lround(size * std::sqrt(double(cascades)))) : size;
        if (o.warmup) renderer.time_frames(s, o.warmup);
        const auto frames = renderer.time_frames(s, o.frames);
        std::vector<std::string> all;
        for (const render::PassTime& p : frames.front())
          if (p.name.find('#') == std::string::npos) all.push_back(p.name);
        const Stats shadow = pass_sum(frames, kShadowMapPasses), frame = pass_sum(frames, all);
        const auto [mae, per_shadowed] = error_against(renderer.render(s), truth);
        const std::string maps = fmt::format("{} x {}²", count, s.shadow_size);
        md += fmt::format("| {} | {} | {:.3f} | {:.3f} | {:.4f} | {:.3f} |\n", name, maps, shadow.median, frame.median,
                          mae, per_shadowed);
        results.push_back({{"technique", name},
                           {"cascades", count},
                           {"shadow_size", s.shadow_size},
                           {"shadow_map_ms", {{"median", shadow.median}, {"p10", shadow.p10}, {"p90", shadow.p90}}},
                           {"frame_ms", {{"median", frame.median}, {"p10", frame.p10}, {"p90", frame.p90}}},
                           {"mae", mae},
                           {"error_per_shadowed_pixel", per_shadowed}});
      }
  fmt::print("{}", md);
  const nlohmann::json doc = {{"device", ctx->info().describe()},
                              {"scene", scene.name},
                              {"resolution", fmt::format("{}x{}", width, height)},
                              {"frames", o.frames},
                              {"warmup", o.warmup},
                              {"msaa", o.frame.settings.msaa},
                              {"cascades", results}};
  write_results(o, doc, md);
}

// The per-technique bench's Markdown (printed) and JSON (--json-file) from its results.
void write_technique_results(const BenchOptions& opt, vk::Context& ctx, const scene::Scene& scene,
                             nlohmann::json& results, const std::vector<std::pair<int, int>>& resolutions,
                             bool host_clock) {
  const std::string md =
      bench_markdown(opt, ctx, scene, results, resolutions, host_clock) + depth_bounds_markdown(results);
  fmt::print("{}", md);
  const nlohmann::json doc = {{"device", ctx.info().describe()},
                              {"scene", scene.name},
                              {"frames", opt.frames},
                              {"warmup", opt.warmup},
                              {"repeats", opt.repeats},
                              {"msaa", opt.frame.settings.msaa},
                              {"filter_size", opt.frame.settings.filter_size},
                              {"shadow_size", opt.frame.settings.shadow_size},
                              {"results", results}};
  write_results(opt, doc, md);
}

// The cascades' depth bounds (the camera's depth pre-pass and its reduction) against the whole
// frame, where the frame has them.
std::optional<nlohmann::json> depth_bounds_json(const std::vector<std::vector<render::PassTime>>& frames) {
  if (!std::ranges::any_of(frames[0], [](const render::PassTime& p) { return p.name == "depth_bounds"; }))
    return std::nullopt;
  std::vector<std::string> all; // every pass of the frame, the depth bounds included
  for (const render::PassTime& p : frames[0]) all.push_back(p.name);
  const Stats bounds = pass_sum(frames, {"depth_bounds"}), frame = pass_sum(frames, all);
  return nlohmann::json{{"median_ms", bounds.median},
                        {"p10_ms", bounds.p10},
                        {"p90_ms", bounds.p90},
                        {"frame_ms", frame.median},
                        {"share_of_frame", bounds.median / frame.median}};
}

void add_bench(CLI::App& app) {
  auto opt = std::make_shared<BenchOptions>();
  auto* cmd = app.add_subcommand("bench", "GPU time per pass, and each technique's cost relative to PCF (shading per "
                                          "pixel, shadow map per texel)");
  add_bench_options(cmd, *opt);
  cmd->callback([opt, cmd] {
    apply_bench_defaults(*opt, *cmd);
    finish_frame_options(opt->frame);
    check_frame_counts(*opt);
    if (!opt->probe.probe.empty()) {
      bench_probe(opt->probe, opt->frame.device, opt->frames, opt->warmup, opt->json, opt->markdown);
      return;
    }
    if (opt->callgrind) check_callgrind();
    const std::vector<std::string> names = bench_techniques(*opt);
    std::vector<std::pair<int, int>> resolutions;
    for (const std::string& r : opt->resolutions) resolutions.push_back(parse_resolution(r));
    validate_configurations(*opt, names, resolutions);
    if (opt->light_kinds) {
      if (opt->callgrind) throw UsageError("--light-kinds and --callgrind: one at a time");
      bench_light_kinds(*opt, names, resolutions);
      return;
    }
    if (opt->against_one_map) {
      if (opt->callgrind) throw UsageError("--against-one-map and --callgrind: one at a time");
      bench_cascades(*opt, names, resolutions);
      return;
    }
    scene::Scene scene = scene_at_frame(opt->frame, load_scene_or_fail(opt->frame.scene));
    if (opt->scattering && !scene.medium)
      throw UsageError(
          fmt::format("--scattering: scene '{}' has no medium (tower, trees, gate and room have one)", scene.name));
    std::unique_ptr<vk::Context> ctx = open_device(opt->frame.device);
    render::Renderer renderer(*ctx, scene);
    check_on_device(renderer, opt->frame, names); // before the first frame, not after some
    if (opt->callgrind) {
      callgrind_prefixes(renderer, opt->frame, names, resolutions[0], opt->shadow_sizes, opt->warmup);
      return;
    }
    const std::vector<std::string>& shadow_passes = kShadowMapPasses;
    // The rectified map's compute passes and the copy: on a CPU device (lavapipe) their timestamps
    // are not the time they take (docs/techniques.md), so there the host clock times them.
    const bool host_clock = ctx->info().type == VK_PHYSICAL_DEVICE_TYPE_CPU;

    const bool tty = isatty(fileno(stderr));
    auto progress = [tty](const std::string& line) { print_progress(tty, line); };
    auto run = [&](render::RenderSettings s) {
      if (opt->warmup) renderer.time_frames(s, opt->warmup);
      return renderer.time_frames(s, opt->frames);
    };
    // --scattering: the shadow-map sizes only for the rectified map of the prefiltered techniques.
    auto sizes_for = [&](const Technique& t) {
      return opt->scattering && !t.prefiltered_scattering() ? std::vector<int>{} : opt->shadow_sizes;
    };
    nlohmann::json results = nlohmann::json::array();
    std::map<std::string, std::map<std::string, double>> per_unit; // technique -> config -> ns per unit
    size_t total = 0, done = 0;
    for (const std::string& name : names)
      total += resolutions.size() + sizes_for(render::find_rendered_technique(name)).size();
    for (const std::string& name : names) {
      nlohmann::json entry = {{"technique", name},
                              {"parameters", viewer::setting_json(settings_for(opt->frame, name), "parameters")},
                              {"shading", nlohmann::json::object()},
                              {"shadow_map", nlohmann::json::object()},
                              {"passes", nlohmann::json::object()}};
      const Technique& technique = render::find_rendered_technique(name);
      const bool scatters = technique.scatters(), prefiltered = technique.prefiltered_scattering();
      for (auto [w, h] : resolutions) {
        render::RenderSettings s = settings_for(opt->frame, name);
        s.width = w;
        s.height = h;
        progress(fmt::format("[{}/{}] {:<26} shading {}x{}", ++done, total, name, w, h));
        auto frames = run(s);
        Stats st = pass_sum(frames, {"surfaces", "shading"}); // deferred shading: both per pixel
        std::string key = fmt::format("{}x{}", w, h);
        double ns = st.median * 1e6 / (double(w) * h);
        per_unit[name]["shading " + key] = ns;
        entry["shading"][key] = {
            {"median_ms", st.median}, {"p10_ms", st.p10}, {"p90_ms", st.p90}, {"ns_per_pixel", ns}};
        if (std::optional<nlohmann::json> bounds = depth_bounds_json(frames)) entry["depth_bounds"][key] = *bounds;
        if (scatters) { // the deferred pass alone (the prefiltered maps: per texel below)
          Stats sc = pass_sum(frames, {"scattering"});
          entry["scattering"][key] = {{"median_ms", sc.median},
                                      {"p10_ms", sc.p10},
                                      {"p90_ms", sc.p90},
                                      {"ns_per_pixel", sc.median * 1e6 / (double(w) * h)}};
        }
        if (key == fmt::format("{}x{}", resolutions[0].first, resolutions[0].second))
          for (const render::PassTime& p : frames[0]) {
            Stats ps = pass_sum(frames, {p.name});
            entry["passes"][p.name] = {{"median_ms", ps.median}, {"p10_ms", ps.p10}, {"p90_ms", ps.p90}};
          }
      }
      for (int size : sizes_for(technique)) {
        render::RenderSettings s = settings_for(opt->frame, name);
        s.width = 320; // the shadow-map passes do not depend on the image size
        s.height = 180;
        s.shadow_size = size;
        progress(fmt::format("[{}/{}] {:<26} shadow map {}²", ++done, total, name, size));
        auto frames = run(s);
        Stats st = pass_sum(frames, shadow_passes);
        if (prefiltered) {
          entry["rectified"][std::to_string(size)] =
              rectified_json(renderer, *ctx, *opt, s, frames, technique, size, host_clock);
        }
        std::string key = std::to_string(size);
        double ns = st.median * 1e6 / (double(size) * size);
        per_unit[name]["shadow " + key] = ns;
        entry["shadow_map"][key] = {
            {"median_ms", st.median}, {"p10_ms", st.p10}, {"p90_ms", st.p90}, {"ns_per_texel", ns}};
      }
      results.push_back(entry);
    }
    if (tty) fmt::print(stderr, "\r{:<70}\r", "");
    add_ratios(results, per_unit);
    write_technique_results(*opt, *ctx, scene, results, resolutions, host_clock);
  });
}

} // namespace msm::tool
