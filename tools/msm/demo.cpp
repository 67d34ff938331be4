// `msm demo` (what `make demo` runs), in three parts:
//  1. filtered hard shadows: the default scene with PCF, VSM, EVSM4, MSM 64, MSM 128 and the
//     non-linearly quantized MSM at 64 and 32 bits side by side, errors against PCF (same kernel);
//  2. single scattering: the `trees` scene (JCGT Fig. 16) rendered at a third of the width and
//     height (shown magnified to the full width) with ray marching (32, 128 samples), CSM-32 and
//     four and six moments, errors in the visible fraction of each view ray against the ray-traced
//     scattering;
//  3. soft shadows: the `models` scene (JCGT Fig. 8) with moment soft shadows (four and six
//     moments) and their baselines VSSM and PCSS, errors against the ray-traced area light;
//  4. image-based lighting (Kneiphof): the `sky_probe` scene rendered at a third of the width and
//     height (shown magnified to the full width), its probe cut into 16, 32 and 64 area lights with mssm6, 32 with pcss and 256 point lights
//     with hard shadows, errors against the full probe's Monte Carlo ground truth.
//  5. light kinds: the default scene under a directional, a spot and a point light in turn (the
//     kinds of scene::light_kinds() the renderer draws; the others are skipped with its message),
//     at a third of the width and height, with MSM 64 and PCF beside the ray-traced hard shadow and
//     their error heat maps (light_kinds.h places the lights).
// Each part writes one labelled image with magnified insets where the techniques differ, and
// prints a table of the errors and the GPU time per pass.
#include "light_kinds.h"
#include "reference_look.h"
#include "render_common.h"
#include "vocabulary.h"

#include "msm/image/compose.h"
#include "msm/image/io.h"
#include "msm/image/metrics.h"
#include "msm/reference/reference.h"
#include "msm/shading.h"
#include "msm/techniques.h"
#include "msm/util/progress.h"
#include "msm/util/statistics.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <unistd.h>

namespace msm::tool {
namespace {

// The parts rendered at a third of the width and height (their ray-traced truths cost the most)
// are drawn as wide as the first part's sheet: each texel shown as `factor`² pixels (nearest, so
// the texels stay visible), which leaves room for the labels and captions the full width has.
image::Image magnified(const image::Image& image, int factor) {
  image::Image out(image.width() * factor, image.height() * factor, image.channel_names());
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int c = 0; c < image.channels(); ++c) out.at(x, y, c) = image.at(x / factor, y / factor, c);
  return out;
}

// The whole-number factor that brings a part rendered `part_width` wide to the sheet width of a
// frame `frame_width` wide.
int sheet_magnification(int frame_width, int part_width) {
  return std::max(1, int(std::lround(double(frame_width) / part_width)));
}

// One comparison: every technique rendered (per technique PNG, EXR, JSON in `out`), a table of
// the errors against `truth` (the ray-traced visibility and its background) or, without it,
// against the first technique, and the GPU time per pass (median of 5 frames); the figure in
// out/figure_name. `truth_rgb` is the first panel where given. `scattering`: the signal is the
// visible fraction of the view rays (background included) against the truth's "visibility".
// `magnification`: the figure's panels and insets shown that many times larger (magnified).
void compare_techniques(render::Renderer& renderer, const vk::Context& ctx, const FrameOptions& frame,
                        const std::vector<std::string>& techniques, const image::Image* truth,
                        const image::Image* truth_rgb, const std::string& out, const std::string& figure_name,
                        bool scattering = false, int magnification = 1) {
  const scene::Scene& scene = renderer.scene();
  bool tty = isatty(fileno(stderr));
  std::vector<render::RenderResult> results;
  std::vector<image::Image> signals;
  for (size_t i = 0; i < techniques.size(); ++i) {
    render::RenderSettings s = settings_for(frame, techniques[i]);
    if (tty) fmt::print(stderr, "\r[{}/{}] {:<26}", i + 1, techniques.size(), s.technique);
    results.push_back(renderer.render(s));
    // The table shows the median of a few more frames: the first one pays for warming up.
    std::vector<std::vector<render::PassTime>> frames = renderer.time_frames(s, 5);
    for (render::PassTime& p : results.back().passes) {
      std::vector<double> ms;
      for (const auto& f : frames)
        for (const render::PassTime& q : f)
          if (q.name == p.name) ms.push_back(q.ms);
      if (!ms.empty()) p.ms = util::median(ms);
    }
    results.back().total_ms = 0;
    for (const render::PassTime& p : results.back().passes) results.back().total_ms += p.ms;
    write_render(out, s.technique, results.back(),
                 render_json(s, scene, 0,
                             scene::shadow_framing_warnings(scene, s.width, s.height, s.shadow_size,
                                                            render::cascade_options(s, scene)),
                             ctx, results.back()));
    signals.push_back(scattering ? results.back().scattering.channel("visible_fraction")
                                 : results.back().shadow.channel("visibility"));
  }
  if (tty) fmt::print(stderr, "\r{:<40}\r", "");

  image::Image mask = truth ? truth->channel("background") : results[0].shadow.channel("background");
  if (scattering) mask = image::Image(mask.width(), mask.height(), 1); // every ray counts
  image::Image reference = truth ? truth->channel("visibility") : signals[0];
  int side = std::max(16, frame.settings.width / 8);
  std::vector<image::Image> candidates = signals;
  if (truth) candidates.insert(candidates.begin(), reference);
  std::vector<image::Rect> insets = image::find_difference_regions(candidates, side, side, 3);
  for (image::Rect& r : insets)
    r = {r.x * magnification, r.y * magnification, r.width * magnification, r.height * magnification};
  std::vector<image::Panel> panels;
  if (truth_rgb) panels.push_back({"ray traced", magnified(*truth_rgb, magnification), "reference"});
  std::vector<std::string> pass_names;
  // Every pass any technique ran, in the order of a frame.
  for (const char* name : {"shadow_depth", "moment_resolve", "translucent", "one_pass_filter", "sat", "blur", "mipmaps",
                           "surfaces", "shading", "rectify", "prefix_sums", "scattering"})
    for (const render::RenderResult& r : results)
      if (std::any_of(r.passes.begin(), r.passes.end(), [&](const render::PassTime& p) { return p.name == name; })) {
        pass_names.push_back(name);
        break;
      }
  std::string header = fmt::format("{:<20} {:>5} {:>8} {:>8} {:>7}", "technique", "bits", "MAE", "leaking", ">3%");
  for (const std::string& p : pass_names) header += fmt::format(" {:>14}", p + " ms");
  fmt::print("\n{} {:>10}\n", header, "total ms");
  for (size_t i = 0; i < results.size(); ++i) {
    const Technique& t = render::find_rendered_technique(techniques[i]);
    image::Metrics m = image::compute_metrics(signals[i], reference, {.mask = &mask});
    std::string line = fmt::format("{:<20} {:>5} {:>8.5f} {:>8.5f} {:>6.2f}%", t.name, t.bits_per_texel, m.mae,
                                   m.light_leaking, 100 * m.share_above_3pct);
    for (const std::string& p : pass_names) {
      double ms = -1;
      for (const render::PassTime& q : results[i].passes)
        if (q.name == p) ms = q.ms;
      line += ms < 0 ? fmt::format(" {:>14}", "-") : fmt::format(" {:>14.3f}", ms);
    }
    fmt::print("{} {:>10.3f}\n", line, results[i].total_ms);
    std::string caption =
        i == 0 && !truth ? std::string("reference") : fmt::format("MAE {:.4f}  leak {:.4f}", m.mae, m.light_leaking);
    panels.push_back({std::string(t.name), magnified(results[i].color, magnification), caption});
  }
  image::ComposeOptions options;
  options.insets = insets;
  options.columns = int(std::min<size_t>(panels.size(), 3));
  image::Image figure = image::compose_comparison(panels, options);
  std::filesystem::path file = std::filesystem::path(out) / figure_name;
  try {
    image::write_png(file, figure);
  } catch (const image::ImageError& e) { throw UsageError(e.what()); }
  fmt::print("\nErrors are in {}; times are GPU timestamps, median of 5 "
             "frames.\nWrote {} ({}x{}) and per technique PNG, shadow-buffer EXR and JSON in {}/\n",
             scattering ? "the visible fraction of each view ray against the ray-traced scattering, every pixel"
             : truth    ? "visibility against the ray-traced area light, background excluded"
                        : "visibility against " + techniques[0] + " (same kernel), background excluded",
             file.string(), figure.width(), figure.height(), out);
}

// The ray tracer's settings of a part: its effect at the part's image size, `samples` per pixel.
reference::Settings reference_settings(reference::Effect effect, const render::RenderSettings& fs, int samples) {
  reference::Settings rs;
  rs.effect = effect;
  rs.width = fs.width;
  rs.height = fs.height;
  rs.samples = samples;
  return rs;
}

// Part 2: single scattering against the ray-traced ground truth (stratified, `samples` per pixel),
// the reference's composite of surface and in-scattered radiance as the first panel (tone mapped
// like the renderer; its background has no sky behind the haze, which the medium hides anyway).
void scatter_part(render::Renderer& renderer, const vk::Context& ctx, const FrameOptions& frame,
                  const scene::Scene& scene, const std::vector<std::string>& techniques, int samples, int magnification,
                  const std::string& out) {
  const render::RenderSettings& fs = frame.settings;
  fmt::print("\nmsm demo: single scattering, scene '{}' at {}x{}, medium σt {}, shadow map {}², ray traced with {} "
             "samples per pixel\n",
             scene.name, fs.width, fs.height, scene.medium->extinction, fs.shadow_size, samples);
  reference::Result truth = reference::render(scene, reference_settings(reference::Effect::scattering, fs, samples));
  image::Image truth_rgb = image::tone_map(truth.radiance, {std::log2(fs.exposure), image::ToneCurve::aces});
  compare_techniques(renderer, ctx, frame, techniques, &truth.visibility, &truth_rgb, out, "scatter-comparison.png",
                     true, magnification);
}

// One configuration of the image-based-lighting part: a technique and the probe's light count.
struct IblCase {
  std::string technique;
  int lights;
};
const std::vector<IblCase> kIblCases = {
    {"mssm6", 16}, {"mssm6", 32}, {"mssm6", 64}, {"pcss", 32}, {"msm-hamburger-64", 256}};

// Part 4: image-based lighting against the full probe's ground truth (`samples` per pixel). Each
// light count is its own cut of the probe (scene::set_probe_light_count) and so its own renderer.
// The error is in the luminance of the tone-mapped images (the look, as scripts/ibl-compare.sh
// measures it), background excluded; it adds the lights' extraction and the shadows.
void ibl_part(const vk::Context& ctx, const FrameOptions& frame, const scene::Scene& scene, int samples,
              int magnification, const std::string& out) {
  const render::RenderSettings& fs = frame.settings;
  fmt::print("\nmsm demo: image-based lighting, scene '{}' at {}x{}, probe {} cut into area lights, shadow map "
             "{}², ray traced from the whole probe with {} samples per pixel\n",
             scene.name, fs.width, fs.height, scene.probe->file.string(), fs.shadow_size, samples);
  reference::Result truth = reference::render(scene, reference_settings(reference::Effect::environment, fs, samples));
  image::Image truth_rgb = reference_look(truth, fs.exposure);
  image::Image mask = truth.visibility.channel("background");
  std::vector<image::Panel> panels = {{"ray traced, whole probe", magnified(truth_rgb, magnification), "reference"}};
  fmt::print("\n{:<20} {:>6} {:>8} {:>7} {:>12}\n", "technique", "lights", "MAE", ">3%", "GPU ms");
  for (const IblCase& c : kIblCases) {
    scene::Scene lit = scene;
    scene::set_probe_light_count(lit, c.lights);
    render::Renderer renderer(ctx, lit);
    render::RenderSettings s = settings_for(frame, c.technique);
    render::RenderResult r = renderer.render(s);
    const std::string name = fmt::format("ibl-{}-{}", c.technique, c.lights);
    write_render(out, name, r,
                 render_json(s, lit, 0,
                             scene::shadow_framing_warnings(lit, s.width, s.height, s.shadow_size,
                                                            render::cascade_options(s, lit)),
                             ctx, r));
    // Both images are R, G, B: the metrics compare their luminance (msm/image/metrics.h).
    image::Metrics m = image::compute_metrics(r.color, truth_rgb, {.mask = &mask});
    fmt::print("{:<20} {:>6} {:>8.5f} {:>6.2f}% {:>12.3f}\n", c.technique, c.lights, m.mae, 100 * m.share_above_3pct,
               r.total_ms);
    panels.push_back({fmt::format("{}, {} lights", c.technique, c.lights), magnified(r.color, magnification),
                      fmt::format("MAE {:.4f}", m.mae)});
  }
  image::ComposeOptions options;
  options.columns = 3;
  image::Image figure = image::compose_comparison(panels, options);
  std::filesystem::path file = std::filesystem::path(out) / "ibl-comparison.png";
  try {
    image::write_png(file, figure);
  } catch (const image::ImageError& e) { throw UsageError(e.what()); }
  fmt::print("\nErrors are in the luminance of the tone-mapped image against the ray-traced whole probe, background "
             "excluded; times are GPU timestamps of one frame.\nWrote {} ({}x{})\n",
             file.string(), figure.width(), figure.height());
}

// Part 5: the scene under one light of each kind (light_kinds.h), each technique beside the
// ray-traced hard shadow and its error heat map (visibility, red where the technique is brighter
// than the truth, blue where darker; full colour at 0.1), one row per kind. A kind the renderer does
// not draw, or draws with none of the techniques, is skipped with its message.
void light_kinds_part(const vk::Context& ctx, const FrameOptions& frame, const scene::Scene& scene,
                      const std::vector<std::string>& techniques, const std::string& out) {
  const render::RenderSettings& fs = frame.settings;
  fmt::print("\nmsm demo: light kinds, scene '{}' at {}x{} under one light of each kind, shadow map {}², against the "
             "traced hard shadow\n\n{:<12} {:<20} {:>8} {:>8} {:>9}\n",
             scene.name, fs.width, fs.height, fs.shadow_size, "light", "technique", "MAE", "leaking", "GPU ms");
  std::vector<image::Panel> panels;
  for (const scene::LightKindInfo& kind : scene::light_kinds()) {
    const scene::Scene lit = scene_under_light_kind(scene, kind.kind);
    std::optional<render::Renderer> renderer;
    try {
      renderer.emplace(ctx, lit);
    } catch (const render::RenderError& e) {
      fmt::print("{:<12} skipped: {}\n", kind.name, e.what());
      continue;
    }
    reference::Result truth = reference::render(lit, reference_settings(reference::Effect::hard, fs, 1));
    const image::Image mask = truth.visibility.channel("background"),
                       reference = truth.visibility.channel("visibility");
    std::vector<image::Panel> row = {
        {fmt::format("{} light, ray traced", kind.name), reference_look(truth, fs.exposure), "reference"}};
    for (const std::string& technique : techniques) {
      render::RenderResult r;
      try {
        r = renderer->render(settings_for(frame, technique));
      } catch (const render::RenderError& e) {
        fmt::print("{:<12} {:<20} skipped: {}\n", kind.name, technique, e.what());
        continue;
      }
      const image::Image signal = r.shadow.channel("visibility");
      const image::Metrics m = image::compute_metrics(signal, reference, {.mask = &mask});
      fmt::print("{:<12} {:<20} {:>8.5f} {:>8.5f} {:>9.3f}\n", kind.name, technique, m.mae, m.light_leaking,
                 r.total_ms);
      row.push_back({technique, r.color, fmt::format("MAE {:.4f}  leak {:.4f}", m.mae, m.light_leaking)});
      row.push_back({technique + " error", image::error_image(signal, reference, 0.1, {.mask = &mask}), ""});
    }
    if (row.size() > 1) panels.insert(panels.end(), row.begin(), row.end());
  }
  if (panels.empty()) {
    fmt::print("msm demo: no light kind drawn with {}: no light-kinds image\n", fmt::join(techniques, ", "));
    return;
  }
  image::ComposeOptions options;
  options.columns = int(1 + 2 * techniques.size());
  image::Image figure = image::compose_comparison(panels, options);
  std::filesystem::path file = std::filesystem::path(out) / "light-kinds-comparison.png";
  try {
    image::write_png(file, figure);
  } catch (const image::ImageError& e) { throw UsageError(e.what()); }
  fmt::print("\nErrors are in visibility against the traced hard shadow, background excluded (heat maps: red "
             "brighter, blue darker than the truth, full colour at 0.1); times are GPU timestamps of one frame.\n"
             "Wrote {} ({}x{})\n",
             file.string(), figure.width(), figure.height());
}

struct DemoOptions {
  FrameOptions frame;
  std::string out = "msm-demo";
  std::vector<std::string> techniques = {"pcf",      "vsm-32",  "evsm4-64", "msm-hamburger-64", "msm-hamburger-128",
                                         "msm-nl64", "msm-nl32"};
  std::string soft_scene = "models";
  std::vector<std::string> soft_techniques = {"mssm4", "mssm6", "vssm", "pcss"};
  int soft_samples = 64;
  std::string scatter_scene = "trees";
  std::vector<std::string> scatter_techniques = {"scatter-march-32", "scatter-march-128", "scatter-csm-32",
                                                 "scatter-msm4-64", "scatter-msm6-96"};
  int scatter_samples = 32;
  std::string ibl_scene = "sky_probe";
  int ibl_samples = 256;
  std::vector<std::string> light_kinds_techniques = {"msm-hamburger-64", "pcf"};
};

// Each part's frame and scene, checked and loaded before the device is opened; a part without its
// scene is skipped.
struct DemoParts {
  scene::Scene scene; // the hard part's
  FrameOptions soft, scatter, ibl;
  std::optional<scene::Scene> soft_scene, scatter_scene, ibl_scene;
};

// The light-kinds part's frame: a third of the width and height (its panels are not magnified).
FrameOptions light_kinds_frame(const DemoOptions& o) {
  FrameOptions f = o.frame;
  f.settings.width = std::max(16, o.frame.settings.width / 3);
  f.settings.height = std::max(16, o.frame.settings.height / 3);
  return f;
}

// The options' own checks: the technique lists made canonical, the sample counts in range.
void check_demo_options(DemoOptions& o) {
  finish_frame_options(o.frame);
  if (o.frame.animation_frame != 0)
    throw UsageError("msm demo draws its scenes as they are (frame 0); --frame is msm render's");
  // `--soft-techniques ""` reaches here as one empty name: it means none (skip the soft part).
  for (auto* list : {&o.techniques, &o.soft_techniques, &o.scatter_techniques, &o.light_kinds_techniques}) {
    std::erase(*list, std::string());
    *list = canonical_technique_names(*list);
  }
  if (o.techniques.empty()) throw UsageError("--techniques: none given");
  if (o.soft_samples < 1 || o.soft_samples > 4096) throw UsageError("--soft-samples must be in [1, 4096]");
  if (o.scatter_samples < 1 || o.scatter_samples > 4096) throw UsageError("--scatter-samples must be in [1, 4096]");
  if (o.ibl_samples < 1 || o.ibl_samples > 4096) throw UsageError("--ibl-samples must be in [1, 4096]");
  validate_techniques(o.frame, o.techniques);
  validate_techniques(light_kinds_frame(o), o.light_kinds_techniques);
}

// The scattering part's frame (a third of the width and height) with its techniques checked.
FrameOptions scatter_frame(const DemoOptions& o) {
  FrameOptions scatter = o.frame;
  scatter.scene = o.scatter_scene;
  scatter.settings.width = std::max(16, o.frame.settings.width / 3);
  scatter.settings.height = std::max(16, o.frame.settings.height / 3);
  if (o.scatter_techniques.empty()) return scatter;
  validate_techniques(scatter, o.scatter_techniques);
  for (const std::string& t : o.scatter_techniques)
    if (!msm_technique_is_scattering(render::find_rendered_technique(t).id))
      throw UsageError(fmt::format("--scatter-techniques: {} is not a scattering technique (msm techniques: "
                                   "scatter-*)",
                                   t));
  return scatter;
}

// The image-based-lighting part's scene, checked with every case's light count.
std::optional<scene::Scene> load_ibl_scene(const FrameOptions& ibl) {
  if (ibl.scene.empty()) return std::nullopt;
  scene::Scene ibl_scene = load_scene_or_fail(ibl.scene);
  if (!ibl_scene.probe)
    throw UsageError(fmt::format("--ibl-scene {}: the scene has no \"probe\" (scenes/README.md)", ibl.scene));
  for (const IblCase& c : kIblCases) {
    validate_techniques(ibl, {c.technique});
    scene::Scene lit = ibl_scene;
    try {
      scene::set_probe_light_count(lit, c.lights);
    } catch (const scene::SceneError& e) { throw UsageError(fmt::format("--ibl-scene {}: {}", ibl.scene, e.what())); }
  }
  return ibl_scene;
}

DemoParts demo_parts(const DemoOptions& o) {
  DemoParts p;
  p.soft = o.frame;
  p.soft.scene = o.soft_scene;
  if (!o.soft_techniques.empty()) validate_techniques(p.soft, o.soft_techniques);
  p.scatter = scatter_frame(o);
  p.scene = load_scene_or_fail(o.frame.scene);
  // The light-kinds part places its lights by the scene's directional light: refused here, before
  // the output directory exists, where it has none.
  if (!o.light_kinds_techniques.empty()) (void)scene_under_light_kind(p.scene, scene::LightKind::directional);
  if (!o.soft_techniques.empty()) p.soft_scene = load_scene_or_fail(p.soft.scene);
  if (!o.scatter_techniques.empty()) {
    p.scatter_scene = load_scene_or_fail(p.scatter.scene);
    if (!p.scatter_scene->medium)
      throw UsageError(
          fmt::format("--scatter-scene {}: the scene has no \"medium\" (scenes/README.md)", p.scatter.scene));
  }
  p.ibl = p.scatter;
  p.ibl.scene = o.ibl_scene;
  // One shadow map per light, up to 256 of them: the paper's 256² (Kneiphof §6), not the hard part's size.
  p.ibl.settings.shadow_size = std::min(p.ibl.settings.shadow_size, 256);
  p.ibl_scene = load_ibl_scene(p.ibl);
  return p;
}

// The soft part: the soft techniques against the ray-traced area light.
void soft_part(render::Renderer& renderer, const vk::Context& ctx, const DemoOptions& o, const DemoParts& p) {
  const render::RenderSettings& fs = o.frame.settings;
  float extent = fs.light_extent_deg ? *fs.light_extent_deg : p.soft_scene->light().angular_extent_deg;
  fmt::print("\nmsm demo: soft shadows, scene '{}' at {}x{}, light {}° across, shadow map {}², ray traced with {} "
             "samples per pixel\n",
             p.soft_scene->name, fs.width, fs.height, extent, fs.shadow_size, o.soft_samples);
  reference::Settings rs = reference_settings(reference::Effect::soft, fs, o.soft_samples);
  // The light the renderer draws: the scene's, or the command line's overrides of it.
  if (fs.light_extent_deg) rs.light_extent_deg = *fs.light_extent_deg;
  if (fs.light_height_deg) rs.light_height_deg = *fs.light_height_deg;
  rs.progress = [lines = std::make_shared<util::ProgressLines>("msm demo: ray tracing ", " rows")](
                    const reference::Progress& progress) {
    if (auto line = lines->next(progress.rows_done, progress.rows_total, progress.seconds))
      fmt::print(stderr, "{}\n", *line);
  };
  reference::Result truth = reference::render(*p.soft_scene, rs);
  image::Image truth_rgb = reference_look(truth, fs.exposure);
  compare_techniques(renderer, ctx, p.soft, o.soft_techniques, &truth.visibility, &truth_rgb, o.out,
                     "soft-comparison.png");
}

void run_demo(DemoOptions& o) {
  check_demo_options(o);
  const DemoParts p = demo_parts(o);
  std::unique_ptr<vk::Context> ctx = open_device(o.frame.device);
  // Both parts' renderers first: what the device cannot do is refused before the output
  // directory exists (the first renderer is released before the soft part).
  std::optional<render::Renderer> hard, soft_renderer, scatter_renderer;
  hard.emplace(*ctx, p.scene);
  check_on_device(*hard, o.frame, o.techniques);
  if (p.soft_scene) {
    soft_renderer.emplace(*ctx, *p.soft_scene);
    check_on_device(*soft_renderer, p.soft, o.soft_techniques);
  }
  if (p.scatter_scene) {
    scatter_renderer.emplace(*ctx, *p.scatter_scene);
    check_on_device(*scatter_renderer, p.scatter, o.scatter_techniques);
  }
  ensure_output_dir(o.out);
  const render::RenderSettings& fs = o.frame.settings;
  fmt::print("msm demo: scene '{}' at {}x{}, shadow map {}² with {}x MSAA, {}² Gaussian (sigma {}), on {}\n",
             p.scene.name, fs.width, fs.height, fs.shadow_size, fs.msaa, fs.filter_size, fs.filter_sigma,
             ctx->info().name);
  compare_techniques(*hard, *ctx, o.frame, o.techniques, nullptr, nullptr, o.out, "comparison.png");
  hard.reset();
  if (!o.light_kinds_techniques.empty())
    light_kinds_part(*ctx, light_kinds_frame(o), p.scene, o.light_kinds_techniques, o.out);
  else
    fmt::print("\nmsm demo: light-kinds part skipped (no --light-kinds-techniques)\n");
  if (p.scatter_scene)
    scatter_part(*scatter_renderer, *ctx, p.scatter, *p.scatter_scene, o.scatter_techniques, o.scatter_samples,
                 sheet_magnification(fs.width, p.scatter.settings.width), o.out);
  else
    fmt::print("\nmsm demo: scattering part skipped (no --scatter-techniques)\n");
  scatter_renderer.reset();
  if (p.ibl_scene)
    ibl_part(*ctx, p.ibl, *p.ibl_scene, o.ibl_samples, sheet_magnification(fs.width, p.ibl.settings.width), o.out);
  else
    fmt::print("\nmsm demo: image-based-lighting part skipped (--ibl-scene \"\")\n");
  if (p.soft_scene)
    soft_part(*soft_renderer, *ctx, o, p);
  else
    fmt::print("\nmsm demo: soft part skipped (no --soft-techniques)\n");
}

} // namespace

void add_demo(CLI::App& app) {
  auto opt = std::make_shared<DemoOptions>();
  opt->frame.settings.width = 960;
  opt->frame.settings.height = 540;
  opt->frame.scene = std::string(scene::default_scene_name());
  auto* cmd = app.add_subcommand(
      "demo", "Render the default scene with PCF, VSM, EVSM4, MSM 64, MSM 128 and the "
              "non-linear MSM 64/32 into one comparison image, then soft shadows (mssm4, "
              "mssm6, vssm, pcss) against the ray-traced area light; print the errors and "
              "the time per pass; single scattering (ray marching, CSM, four and six moments) against the ray-traced "
              "scattering, and image-based lighting (a probe cut into 16-256 area lights) against the whole "
              "probe, in between");
  add_term(cmd, "--out", opt->out)->capture_default_str();
  add_term(cmd, "--techniques", opt->techniques, ", to compare (the first is the reference)")->delimiter(',');
  cmd->add_option("--soft-scene", opt->soft_scene, "Scene of the soft-shadow part")->capture_default_str();
  cmd->add_option("--soft-techniques", opt->soft_techniques, "Soft techniques or aliases (\"\": skip the soft part)")
      ->delimiter(',');
  cmd->add_option("--soft-samples", opt->soft_samples, "Ray-traced samples per pixel of the area-light reference")
      ->capture_default_str();
  cmd->add_option("--scatter-scene", opt->scatter_scene,
                  "Scene of the single-scattering part (rendered at a third of the width and height; needs a medium)")
      ->capture_default_str();
  cmd->add_option("--scatter-techniques", opt->scatter_techniques,
                  "Scattering techniques (\"\": skip the scattering part)")
      ->delimiter(',');
  cmd->add_option("--scatter-samples", opt->scatter_samples, "Ray-traced samples per pixel of the scattering reference")
      ->capture_default_str();
  cmd->add_option("--ibl-scene", opt->ibl_scene,
                  "Scene of the image-based-lighting part (needs a \"probe\"; rendered at a third of the width and "
                  "height; \"\": skip the part)")
      ->capture_default_str();
  cmd->add_option("--ibl-samples", opt->ibl_samples, "Ray-traced samples per pixel of the whole probe's ground truth")
      ->capture_default_str();
  cmd->add_option("--light-kinds-techniques", opt->light_kinds_techniques,
                  "Techniques of the light-kinds part: the scene under a directional, a spot and a point light, at a "
                  "third of the width and height, against the traced hard shadow (\"\": skip the part)")
      ->delimiter(',');
  add_frame_options(cmd, opt->frame);
  cmd->callback([opt] { run_demo(*opt); });
}

} // namespace msm::tool
