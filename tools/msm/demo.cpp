// `msm demo` (what `make demo` runs): the default scene with PCF, VSM, EVSM4, MSM 64, MSM 128 and
// the non-linearly quantized MSM at 64 and 32 bits side by side in one labelled image with magnified insets where they differ, and a table of the
// error against the PCF reference and the GPU time per pass.
#include "render_common.h"

#include "msm/image/compose.h"
#include "msm/image/io.h"
#include "msm/image/metrics.h"

#include <fmt/core.h>

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace msm::tool {

void add_demo(CLI::App& app) {
  struct Options {
    FrameOptions frame;
    std::string out = "msm-demo";
    std::vector<std::string> techniques = {"pcf",          "vsm-32",   "evsm4-64", "msm-hamburger-64", "msm-hamburger-128",
                                           "msm-nl64", "msm-nl32"};
  };
  auto opt = std::make_shared<Options>();
  opt->frame.settings.width = 960;
  opt->frame.settings.height = 540;
  opt->frame.scene = std::string(scene::default_scene_name());
  auto* cmd = app.add_subcommand("demo", "Render the default scene with PCF, VSM, EVSM4, MSM 64, MSM 128 and the "
                                         "non-linear MSM 64/32 into one comparison image, and print the error against PCF and the time per pass");
  cmd->add_option("--out,-o", opt->out, "Output directory")->capture_default_str();
  cmd->add_option("--techniques", opt->techniques, "Techniques to compare (the first is the reference)")
      ->delimiter(',');
  add_frame_options(cmd, opt->frame);
  cmd->callback([opt] {
    finish_frame_options(opt->frame);
    if (opt->techniques.empty()) throw UsageError("--techniques: none given");
    validate_techniques(opt->frame, opt->techniques);
    scene::Scene scene = load_scene_or_fail(opt->frame.scene);
    ensure_output_dir(opt->out);
    std::unique_ptr<vk::Context> ctx = open_device(opt->frame.device);
    render::Renderer renderer(*ctx, scene);
    fmt::print("msm demo: scene '{}' at {}x{}, shadow map {}² with {}x MSAA, {}² Gaussian (sigma {}), on {}\n",
               scene.name, opt->frame.settings.width, opt->frame.settings.height, opt->frame.settings.shadow_size,
               opt->frame.settings.msaa, opt->frame.settings.filter_size, opt->frame.settings.filter_sigma,
               ctx->info().name);

    bool tty = isatty(fileno(stderr));
    std::vector<render::RenderResult> results;
    std::vector<image::Image> signals;
    for (size_t i = 0; i < opt->techniques.size(); ++i) {
      render::RenderSettings s = settings_for(opt->frame, opt->techniques[i]);
      if (tty) fmt::print(stderr, "\r[{}/{}] {:<26}", i + 1, opt->techniques.size(), s.technique);
      results.push_back(renderer.render(s));
      // The table shows the median of a few more frames: the first one pays for warming up.
      std::vector<std::vector<render::PassTime>> frames = renderer.time_frames(s, 5);
      for (render::PassTime& p : results.back().passes) {
        std::vector<double> ms;
        for (const auto& frame : frames)
          for (const render::PassTime& q : frame)
            if (q.name == p.name) ms.push_back(q.ms);
        std::nth_element(ms.begin(), ms.begin() + std::ptrdiff_t(ms.size() / 2), ms.end());
        p.ms = ms.empty() ? p.ms : ms[ms.size() / 2];
      }
      results.back().total_ms = 0;
      for (const render::PassTime& p : results.back().passes) results.back().total_ms += p.ms;
      write_render(opt->out, s.technique, results.back(), render_json(s, scene, *ctx, results.back()));
      signals.push_back(results.back().shadow.channel("visibility"));
    }
    if (tty) fmt::print(stderr, "\r{:<40}\r", "");

    // Error against the first technique (PCF), background masked.
    image::Image mask = results[0].shadow.channel("background");
    int side = std::max(16, opt->frame.settings.width / 8);
    std::vector<image::Rect> insets = image::find_difference_regions(signals, side, side, 3);
    std::vector<image::Panel> panels;
    std::vector<std::string> pass_names;
    // Every pass any technique ran, in the order of a frame.
    for (const char* name : {"shadow_depth", "moment_resolve", "translucent", "one_pass_filter", "sat", "blur",
                             "mipmaps", "shading"})
      for (const render::RenderResult& r : results)
        if (std::any_of(r.passes.begin(), r.passes.end(), [&](const render::PassTime& p) { return p.name == name; })) {
          pass_names.push_back(name);
          break;
        }
    std::string header = fmt::format("{:<20} {:>5} {:>8} {:>8} {:>7}", "technique", "bits", "MAE", "leaking", ">3%");
    for (const std::string& p : pass_names) header += fmt::format(" {:>14}", p + " ms");
    fmt::print("\n{} {:>10}\n", header, "total ms");
    for (size_t i = 0; i < results.size(); ++i) {
      const render::Technique& t = render::find_technique(opt->techniques[i]);
      image::Metrics m = image::compute_metrics(signals[i], signals[0], {.mask = &mask});
      std::string line = fmt::format("{:<20} {:>5} {:>8.5f} {:>8.5f} {:>6.2f}%", t.name, t.bits_per_texel, m.mae,
                                     m.light_leaking, 100 * m.share_above_3pct);
      for (const std::string& p : pass_names) {
        double ms = -1;
        for (const render::PassTime& q : results[i].passes)
          if (q.name == p) ms = q.ms;
        line += ms < 0 ? fmt::format(" {:>14}", "-") : fmt::format(" {:>14.3f}", ms);
      }
      fmt::print("{} {:>10.3f}\n", line, results[i].total_ms);
      std::string caption = i == 0 ? std::string("reference") : fmt::format("MAE {:.4f}  leak {:.4f}", m.mae, m.light_leaking);
      panels.push_back({std::string(t.name), results[i].color, caption});
    }
    image::ComposeOptions options;
    options.insets = insets;
    options.columns = int(std::min<size_t>(panels.size(), 3));
    image::Image figure = image::compose_comparison(panels, options);
    std::filesystem::path file = std::filesystem::path(opt->out) / "comparison.png";
    try {
      image::write_png(file, figure);
    } catch (const image::ImageError& e) {
      throw UsageError(e.what());
    }
    fmt::print("\nErrors are in visibility against {} (same kernel), background excluded; times are GPU "
               "timestamps, median of 5 frames.\nWrote {} ({}x{}) and per technique PNG, shadow-buffer EXR and JSON in {}/\n",
               opt->techniques[0], file.string(), figure.width(), figure.height(), opt->out);
  });
}

} // namespace msm::tool
