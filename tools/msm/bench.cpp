// `msm bench`: GPU time per pass over repeated frames (median and spread), and per technique the
// cost relative to PCF with the same kernel: shading per pixel at the given resolutions, shadow
// map (depth, resolve, blur, mips) per texel at the given sizes. JSON and a markdown table.
#include "probe_bench.h"
#include "render_common.h"

#include "msm/image/io.h"
#include "msm/techniques.h"
#include "msm/util/statistics.h"
#include "msm/vk/vk.h"

#include <fmt/core.h>

#include <algorithm>
#include <cstdio>
#include <map>
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

// The device's copy bandwidth, the bound of the prefix sums (JCGT App. C): vkCmdCopyImage of an
// RGBA32F image of size² texels (16 B read and 16 B written per texel), median over `runs`
// submissions after one warm-up. Returns the copy's milliseconds.
double copy_ms(const vk::Context& ctx, uint32_t size, int runs) {
  const VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  vk::Image from = vk::create_image(
      ctx, vk::ImageDesc{.width = size, .height = size, .format = VK_FORMAT_R32G32B32A32_SFLOAT, .usage = usage});
  vk::Image to = vk::create_image(
      ctx, vk::ImageDesc{.width = size, .height = size, .format = VK_FORMAT_R32G32B32A32_SFLOAT, .usage = usage});
  // Written once from the host (an image never written may not be copied at full cost).
  std::vector<float> zeros(size_t(size) * size * 4, 0.5f);
  vk::upload_image(ctx, from, std::as_bytes(std::span(zeros)), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
  vk::GpuTimer timer(ctx);
  std::vector<double> times;
  for (int r = 0; r <= runs; ++r) {
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
      for (const vk::Image* image : {&to})
        vk::pipeline_barrier(cmd, vk::image_barrier(image->handle(), image->aspect(),
                                                    VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                                    VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                                    VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                    VK_IMAGE_LAYOUT_GENERAL));
      timer.reset(cmd);
      timer.begin(cmd, "copy");
      VkImageCopy region{.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                         .srcOffset = {0, 0, 0},
                         .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                         .dstOffset = {0, 0, 0},
                         .extent = {size, size, 1}};
      vkCmdCopyImage(cmd, from.handle(), VK_IMAGE_LAYOUT_GENERAL, to.handle(), VK_IMAGE_LAYOUT_GENERAL, 1, &region);
      timer.end(cmd);
    });
    if (r > 0) times.push_back(timer.read().total("copy"));
  }
  return util::median(times);
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
          renderer.submit_frame_prefix(s, k);
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

} // namespace

void add_bench(CLI::App& app) {
  struct Options {
    FrameOptions frame;
    std::vector<std::string> techniques;
    std::vector<std::string> resolutions = {"1920x1080", "3840x2160"};
    std::vector<int> shadow_sizes = {1024, 2048};
    int frames = 20, warmup = 2;
    std::string json, markdown;
    bool callgrind = false;
    ProbeBench probe;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("bench", "GPU time per pass, and each technique's cost relative to PCF (shading per "
                                          "pixel, shadow map per texel)");
  cmd->add_option("--techniques", opt->techniques, "Techniques or aliases (default: all)")->delimiter(',');
  cmd->add_option("--resolutions", opt->resolutions, "Image sizes for the shading cost")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--shadow-sizes", opt->shadow_sizes, "Shadow map sizes for the shadow-map cost")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--frames", opt->frames, "Timed frames per configuration")->capture_default_str();
  cmd->add_option("--warmup", opt->warmup, "Untimed frames first")->capture_default_str();
  cmd->add_option("--json", opt->json, "Write the results as JSON here");
  cmd->add_option("--markdown", opt->markdown, "Write the results as a markdown table here");
  cmd->add_flag("--callgrind", opt->callgrind,
                "Under valgrind --tool=callgrind --instr-atstart=no: one callgrind dump per prefix of each frame "
                "(first resolution, each shadow size) instead of times; scripts/callgrind-passes.sh turns them into "
                "instructions per pass");
  cmd->add_option("--probe", opt->probe.probe,
                  "Time the light-probe pipeline instead (an equirectangular EXR, or 'sky'): cube map, tables and "
                  "median cut on the device against face size and light count");
  cmd->add_option("--probe-sizes", opt->probe.sizes, "Face sizes for --probe")->delimiter(',')->capture_default_str();
  cmd->add_option("--probe-lights", opt->probe.lights, "Light counts for --probe")
      ->delimiter(',')
      ->capture_default_str();
  add_frame_options(cmd, opt->frame);
  cmd->callback([opt] {
    finish_frame_options(opt->frame);
    if (opt->frames < 1 || opt->frames > 10000) throw UsageError("--frames must be in [1, 10000]");
    if (opt->warmup < 0 || opt->warmup > 1000) throw UsageError("--warmup must be in [0, 1000]");
    if (!opt->probe.probe.empty()) {
      bench_probe(opt->probe, opt->frame.device, opt->frames, opt->warmup, opt->json, opt->markdown);
      return;
    }
    if (opt->callgrind) check_callgrind();
    std::vector<std::string> names = canonical_technique_names(opt->techniques);
    if (names.empty())
      for (const Technique* t : render::rendered_techniques()) names.emplace_back(t->name);
    if (!opt->callgrind && std::find(names.begin(), names.end(), "pcf") == names.end())
      names.insert(names.begin(), "pcf");
    std::vector<std::pair<int, int>> resolutions;
    for (const std::string& r : opt->resolutions) resolutions.push_back(parse_resolution(r));
    // Validate every configuration before the first frame.
    for (const std::string& name : names) {
      render::RenderSettings s = settings_for(opt->frame, name);
      try {
        for (auto [w, h] : resolutions) {
          s.width = w;
          s.height = h;
          s.validate();
        }
        for (int size : opt->shadow_sizes) {
          s.shadow_size = size;
          s.validate();
        }
      } catch (const render::RenderError& e) { throw UsageError(e.what()); }
    }
    scene::Scene scene = load_scene_or_fail(opt->frame.scene);
    std::unique_ptr<vk::Context> ctx = open_device(opt->frame.device);
    render::Renderer renderer(*ctx, scene);
    check_on_device(renderer, opt->frame, names); // before the first frame, not after some
    if (opt->callgrind) {
      callgrind_prefixes(renderer, opt->frame, names, resolutions[0], opt->shadow_sizes, opt->warmup);
      return;
    }
    const std::vector<std::string> shadow_passes = {"shadow_depth", "moment_resolve",  "translucent", "blur",
                                                    "mipmaps",      "one_pass_filter", "sat"};

    // A progress line: rewritten in place on a terminal, one line per step in a log.
    bool tty = isatty(fileno(stderr));
    auto progress = [&](const std::string& line) {
      if (tty)
        fmt::print(stderr, "\r{:<70}", line);
      else
        fmt::print(stderr, "{}\n", line);
    };
    auto run = [&](render::RenderSettings s) {
      if (opt->warmup) renderer.time_frames(s, opt->warmup);
      return renderer.time_frames(s, opt->frames);
    };
    nlohmann::json results = nlohmann::json::array();
    std::map<std::string, std::map<std::string, double>> per_unit; // technique -> config -> ns per unit
    size_t total = names.size() * (resolutions.size() + opt->shadow_sizes.size()), done = 0;
    for (const std::string& name : names) {
      nlohmann::json entry = {{"technique", name},
                              {"shading", nlohmann::json::object()},
                              {"shadow_map", nlohmann::json::object()},
                              {"passes", nlohmann::json::object()}};
      const int id = render::find_rendered_technique(name).id;
      const bool scatters = msm_technique_is_scattering(id), prefiltered = msm_technique_is_prefiltered_scattering(id);
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
      for (int size : opt->shadow_sizes) {
        render::RenderSettings s = settings_for(opt->frame, name);
        s.width = 320; // the shadow-map passes do not depend on the image size
        s.height = 180;
        s.shadow_size = size;
        progress(fmt::format("[{}/{}] {:<26} shadow map {}²", ++done, total, name, size));
        auto frames = run(s);
        Stats st = pass_sum(frames, shadow_passes);
        if (prefiltered) {
          // The rectified map and its prefix sums per texel, the prefix sums against the copy bound:
          // the bytes they read and write per texel over the copy's 32.
          Stats rect = pass_sum(frames, {"rectify"}), prefix = pass_sum(frames, {"prefix_sums"});
          double copy = copy_ms(*ctx, uint32_t(size), std::max(opt->frames, 3));
          const glm::ivec2 bytes = msm_technique_scatter_map_bytes(id);
          double bound = copy * double(bytes.x + bytes.y) / 32.0;
          entry["rectified"][std::to_string(size)] = {
              {"rectify_ms", rect.median},     {"prefix_sums_ms", prefix.median},
              {"copy_rgba32f_ms", copy},       {"bandwidth_gb_s", 32.0 * size * size / (copy * 1e6)},
              {"prefix_sums_bound_ms", bound}, {"fraction_of_bound", bound / prefix.median}};
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
    // Ratios to PCF; the soft techniques' shading also to PCSS where it ran (JCGT §4: two table
    // queries against hundreds of taps).
    bool with_pcss = per_unit.count("pcss") > 0;
    for (nlohmann::json& entry : results) {
      const std::string name = entry["technique"];
      for (auto& [key, value] : entry["shading"].items()) {
        value["ratio_to_pcf"] = per_unit[name]["shading " + key] / per_unit["pcf"]["shading " + key];
        if (with_pcss && msm_technique_is_area_light(render::find_rendered_technique(name).id))
          value["ratio_to_pcss"] = per_unit[name]["shading " + key] / per_unit["pcss"]["shading " + key];
      }
      for (auto& [key, value] : entry["shadow_map"].items())
        value["ratio_to_pcf"] = per_unit[name]["shadow " + key] / per_unit["pcf"]["shadow " + key];
    }

    std::string md = fmt::format("Device: {}. Scene '{}', {} frames per configuration (median; p10–p90 in JSON), "
                                 "{}x MSAA, {}² Gaussian.\n\n| technique |",
                                 ctx->info().describe(), scene.name, opt->frames, opt->frame.settings.msaa,
                                 opt->frame.settings.filter_size);
    for (auto [w, h] : resolutions) md += fmt::format(" shading {}x{} ms (× PCF) |", w, h);
    for (int size : opt->shadow_sizes) md += fmt::format(" shadow map {}² ms (× PCF) |", size);
    md += "\n|---|";
    for (size_t i = 0; i < resolutions.size() + opt->shadow_sizes.size(); ++i) md += "---:|";
    md += "\n";
    for (const nlohmann::json& entry : results) {
      md += fmt::format("| {} |", entry["technique"].get<std::string>());
      for (auto [w, h] : resolutions) {
        const auto& v = entry["shading"][fmt::format("{}x{}", w, h)];
        md += fmt::format(" {:.3f} ({:.2f}) |", v["median_ms"].get<double>(), v["ratio_to_pcf"].get<double>());
      }
      for (int size : opt->shadow_sizes) {
        const auto& v = entry["shadow_map"][std::to_string(size)];
        md += fmt::format(" {:.3f} ({:.2f}) |", v["median_ms"].get<double>(), v["ratio_to_pcf"].get<double>());
      }
      md += "\n";
    }
    if (with_pcss) {
      md += fmt::format("\nSoft shadows, shading time relative to pcss ({}² search):",
                        opt->frame.settings.soft_kernel ? opt->frame.settings.soft_kernel : render::kDefaultPcssKernel);
      for (const nlohmann::json& entry : results)
        for (auto [w, h] : resolutions) {
          const auto& v = entry["shading"][fmt::format("{}x{}", w, h)];
          if (v.contains("ratio_to_pcss") && entry["technique"] != "pcss")
            md += fmt::format(" {} {}x{}: {:.3f};", entry["technique"].get<std::string>(), w, h,
                              v["ratio_to_pcss"].get<double>());
        }
      md += "\n";
    }
    // Scattering: the deferred pass per pixel against ray marching in the same run, and the prefiltered
    // maps per texel with the prefix sums against the copy bound.
    bool any_scattering = false;
    for (const nlohmann::json& entry : results) any_scattering = any_scattering || entry.contains("scattering");
    if (any_scattering) {
      md += "\nSingle scattering, the scattering pass alone: ms (ns per pixel; × scatter-march-128, × scatter-march-32 "
            "where they ran)\n\n| technique |";
      for (auto [w, h] : resolutions) md += fmt::format(" {}x{} |", w, h);
      md += "\n|---|";
      for (size_t i = 0; i < resolutions.size(); ++i) md += "---:|";
      md += "\n";
      auto pass_ns = [&](const std::string& technique, const std::string& key) {
        for (const nlohmann::json& e : results)
          if (e["technique"] == technique && e.contains("scattering"))
            return e["scattering"][key]["ns_per_pixel"].get<double>();
        return 0.0;
      };
      for (nlohmann::json& entry : results) {
        if (!entry.contains("scattering")) continue;
        md += fmt::format("| {} |", entry["technique"].get<std::string>());
        for (auto [w, h] : resolutions) {
          std::string key = fmt::format("{}x{}", w, h);
          nlohmann::json& v = entry["scattering"][key];
          double ns = v["ns_per_pixel"].get<double>();
          md += fmt::format(" {:.3f} ({:.1f}", v["median_ms"].get<double>(), ns);
          for (const char* march : {"scatter-march-128", "scatter-march-32"})
            if (double m = pass_ns(march, key); m > 0.0) {
              v[std::string("ratio_to_") + march] = ns / m;
              md += fmt::format("; {:.3f}", ns / m);
            }
          md += ") |";
        }
        md += "\n";
      }
      for (const nlohmann::json& entry : results) {
        if (!entry.contains("rectified")) continue;
        md += fmt::format("\n{}: rectified map per size: rectify ms, prefix sums ms, bound ms (copy bandwidth), "
                          "fraction of the bound:",
                          entry["technique"].get<std::string>());
        for (auto& [size, v] : entry["rectified"].items())
          md += fmt::format(" {}²: {:.3f}, {:.3f}, {:.3f} ({:.1f} GB/s), {:.2f};", size, v["rectify_ms"].get<double>(),
                            v["prefix_sums_ms"].get<double>(), v["prefix_sums_bound_ms"].get<double>(),
                            v["bandwidth_gb_s"].get<double>(), v["fraction_of_bound"].get<double>());
        md += "\n";
      }
    }
    fmt::print("{}", md);
    nlohmann::json doc = {{"device", ctx->info().describe()},
                          {"scene", scene.name},
                          {"frames", opt->frames},
                          {"warmup", opt->warmup},
                          {"msaa", opt->frame.settings.msaa},
                          {"filter_size", opt->frame.settings.filter_size},
                          {"results", results}};
    auto write = [](const std::string& path, const std::string& text) {
      try {
        image::write_file_atomic(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
      } catch (const image::ImageError& e) { throw UsageError(e.what()); }
    };
    if (!opt->json.empty()) write(opt->json, doc.dump(2) + "\n");
    if (!opt->markdown.empty()) write(opt->markdown, md);
  });
}

} // namespace msm::tool
