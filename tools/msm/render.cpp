// `msm render`: one or more techniques on one scene; `msm scenes`: the built-in scenes.
#include "frames.h"
#include "render_common.h"
#include "vocabulary.h"

#include "msm/util/text.h"
#include "msm/viewer/view_file.h"

#include <fmt/core.h>

#include <chrono>
#include <cstdio>
#include <optional>

namespace msm::tool {
namespace {

// The options of msm render, as given.
struct RenderOptions {
  FrameOptions frame;
  std::string techniques = "msm-hamburger-64";
  std::string out = "msm-render";
  std::string view; // a view file (msm view)
  Frames frames;
  std::string probe;             // a probe instead of the scene's lighting (scene::set_probe)
  std::optional<int> lights;     // the probe's area lights (scene::set_probe_light_count)
  std::optional<int> sub_lights; // and their sub-lights
};

// --view: the view file's scene, camera, animated objects' frame and settings (its technique unless
// -t is given); only -t, -o and --device go with it (UsageError otherwise).
struct ViewGiven {
  std::optional<scene::Camera> camera;
  int object_frame = 0;
  std::optional<std::vector<viewer::ViewLight>> lights; // every light of the view (the viewer's)
};
ViewGiven apply_view(RenderOptions& o, const CLI::App& cmd) {
  ViewGiven given;
  for (const CLI::Option* option : cmd.get_options()) {
    const std::vector<std::string>& long_names = option->get_lnames();
    std::string name = long_names.empty() ? option->get_name() : long_names.front();
    if (option->count() > 0 && name != "view" && name != "out" && name != "techniques" && name != "technique" &&
        name != "device")
      throw UsageError(fmt::format("--view sets the scene and every setting; --{} cannot go with it", name));
  }
  try {
    viewer::View view = viewer::load_view(o.view);
    o.frame.settings = view.settings;
    o.frame.scene = view.scene;
    given.camera = view.camera;
    given.object_frame = view.object_frame;
    given.lights = view.lights;
    if (cmd.count("--techniques") + cmd.count("--technique") == 0) o.techniques = view.settings.technique;
  } catch (const viewer::ViewError& e) { throw UsageError(e.what()); }
  return given;
}

} // namespace

void add_render(CLI::App& app) {
  auto opt = std::make_shared<RenderOptions>();
  auto* cmd = app.add_subcommand("render", "Render a scene with one or more shadow techniques (PNG, shadow-buffer "
                                           "EXR and JSON per technique)");
  add_deprecated_option(cmd, "--technique", "-t/--techniques", opt->techniques)->delimiter(',');
  add_term(cmd, "--techniques", opt->techniques, ", or 'all'")->capture_default_str();
  add_term(cmd, "--out", opt->out)->capture_default_str();
  cmd->add_option("--view", opt->view,
                  "A view file of msm view (scene, camera, lights, every setting), or a render's JSON output: "
                  "renders exactly that view; only -t, -o and --device go with it");
  add_frame_options(cmd, opt->frame);
  cmd->add_option("--frames", opt->frames.frames,
                  "Frames to render of a dynamic scene, with their timings: each frame splits the scene's (turned) "
                  "light probe into its area lights again on the device, and moves its animated objects (an "
                  "object's \"motion\"; frames.h)")
      ->check(integer_range("--frames", 1, 10000));
  add_term(cmd, "--probe-rotation-speed", opt->frames.rotation_speed_deg, " (with --frames)");
  add_term(cmd, "--probe", opt->probe,
           ": lights the scene instead of its own lights (image-based lighting; the scene's probe settings are "
           "kept, else 32 lights, 128² per face)");
  add_term(cmd, "--lights", opt->lights, " (default: the scene's)");
  add_term(cmd, "--sub-lights", opt->sub_lights,
           ", whose unshadowed light each area light sums (default: the scene's \"sub_lights\")");
  cmd->callback([opt, cmd] {
    const bool frames = cmd->count("--frames") > 0 || cmd->count("--probe-rotation-speed") > 0;
    ViewGiven view;
    if (!opt->view.empty())
      view = apply_view(*opt, *cmd);
    else
      finish_frame_options(opt->frame);
    std::vector<std::string> names;
    if (opt->techniques == "all")
      for (const Technique* t : render::rendered_techniques()) names.emplace_back(t->name);
    else
      names = canonical_technique_names(util::split_nonempty(opt->techniques, ','));
    if (names.empty()) throw UsageError("--techniques: no technique given");
    validate_techniques(opt->frame, names);
    scene::Scene scene = load_scene_or_fail(opt->frame.scene);
    if (view.camera) scene.camera = *view.camera;
    if (view.lights) viewer::apply_view_lights(*view.lights, scene);
    if (view.object_frame > 0) scene = scene::at_frame(scene, view.object_frame); // the view's animated objects
    if (frames && opt->frame.animation_frame > 0)
      throw UsageError(fmt::format("--frame {} renders one frame of the scene, --frames a sequence from frame 0: give "
                                   "one of them",
                                   opt->frame.animation_frame));
    scene = scene_at_frame(opt->frame, std::move(scene));
    const int frame = view.object_frame > 0 ? view.object_frame : opt->frame.animation_frame;
    if (!opt->probe.empty()) try {
        scene::set_probe(scene, opt->probe);
      } catch (const scene::SceneError& e) { throw UsageError(e.what()); }
    if (opt->lights || opt->sub_lights) try {
        scene::set_probe_light_count(scene, opt->lights.value_or(scene.probe ? scene.probe->lights : 1),
                                     opt->sub_lights);
      } catch (const scene::SceneError& e) { throw UsageError(e.what()); }
    const render::RenderSettings& f = opt->frame.settings;
    const std::vector<std::string> warnings =
        scene::shadow_framing_warnings(scene, f.width, f.height, f.shadow_size, render::cascade_options(f, scene));
    for (const std::string& w : warnings) fmt::print(stderr, "msm render: {}\n", w);
    check_limits(opt->frame, scene, names);
    if (frames) check_frames(scene, opt->frames);
    std::unique_ptr<vk::Context> ctx = open_device(opt->frame.device);
    fmt::print(stderr, "msm render: scene '{}', {} triangles, {}x{}, shadow map {}², on {}\n", scene.name,
               scene.triangle_count(), f.width, f.height, f.shadow_size, ctx->info().name);
    render::Renderer renderer(*ctx, scene);
    // What the device cannot do is refused before the output directory exists.
    check_on_device(renderer, opt->frame, names);
    if (frames) {
      ensure_output_dir(opt->out);
      render_frames(*ctx, renderer, scene, opt->frame, names, opt->out, opt->frames);
      return;
    }
    // The directory is made once the first technique has rendered (a render the device cannot
    // hold leaves none), and every technique's files are renamed into it together at the end: an
    // interrupted or failed run leaves the directory as the last complete run left it, never one
    // run's files of some techniques beside another's (the temporaries of an interrupted run are
    // hidden files, ".<name>.tmp.<pid>.<n>").
    check_output_dir(opt->out);
    image::FileSet files;
    for (size_t i = 0; i < names.size(); ++i) {
      render::RenderSettings s = settings_for(opt->frame, names[i]);
      render::RenderResult result;
      // GPU time is the frame's passes (timestamps); wall time adds recording, read-back and the files.
      auto start = std::chrono::steady_clock::now();
      // One technique can take long (a large shadow map on a CPU device): say what is running.
      if (names.size() == 1) fmt::print(stderr, "msm render: rendering {} ...\n", names[i]);
      try {
        result = renderer.render(s);
      } catch (const render::RenderError& e) { throw UsageError(e.what()); }
      for (const std::string& w : result.warnings) fmt::print(stderr, "msm render: {} ({})\n", w, names[i]);
      if (i == 0) ensure_output_dir(opt->out);
      write_render(files, opt->out, names[i], result, render_json(s, scene, frame, warnings, *ctx, result));
      double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      fmt::print(stderr, "[{}/{}] {:<26} {:8.2f} ms GPU {:8.0f} ms wall -> {}/{}.png{}{}\n", i + 1, names.size(),
                 names[i], result.total_ms, wall_ms, opt->out, names[i],
                 result.shadow_rgb.empty() ? "" : fmt::format(", {}-rgb.exr (visibility per colour channel)", names[i]),
                 result.scattering.empty() ? "" : fmt::format(", {}-scattering.exr", names[i]));
    }
    try {
      files.commit();
    } catch (const image::ImageError& e) { throw UsageError(e.what()); }
  });
}

void add_scenes(CLI::App& app) {
  auto* cmd = app.add_subcommand("scenes", "List the built-in scenes (each is also scenes/<name>.json)");
  cmd->callback([] {
    for (const std::string& name : scene::builtin_scene_names()) {
      scene::Scene s = scene::builtin_scene(name);
      fmt::print("{:<10} {:>8} triangles{}\n", name, s.triangle_count(),
                 name == scene::default_scene_name() ? "  (default)" : "");
    }
  });
}

} // namespace msm::tool
