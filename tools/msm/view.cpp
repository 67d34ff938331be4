// `msm view`: the interactive viewer (src/viewer), where the build has it (MSM_BUILD_VIEWER).
#include "render_common.h"
#include "vocabulary.h"

#include "msm/viewer/script.h"
#include "msm/viewer/view_file.h"
#if MSM_TOOL_VIEWER
#include "msm/viewer/viewer.h"
#endif

#include <fmt/core.h>

namespace msm::tool {

void add_view(CLI::App& app) {
  struct Options {
    std::string scene = "fence", technique, view_file, script_file, device;
    int width = 1280, height = 720;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("view", "Interactive viewer: every technique live, split screen, GPU time per pass "
                                         "(a window; on a headless machine use xvfb-run)");
  auto* scene = add_term(cmd, "--scene", opt->scene)->capture_default_str();
  add_term(cmd, "--technique", opt->technique, ": the one to start with");
  cmd->add_option("--view", opt->view_file, "Start from this view file (scene, camera, lights, settings)")
      ->excludes(scene);
  cmd->add_option("--script", opt->script_file,
                  "Run these actions, one per frame (technique, set, camera, light, light-add, light-move, "
                  "light-set, light-on, light-off, light-remove, split, screenshot, resize, quit, ...: "
                  "docs/viewer.md)");
  add_term(cmd, "--width", opt->width, ": the window's")
      ->capture_default_str()
      ->check(integer_range("--width", 64, 8192));
  add_term(cmd, "--height", opt->height, ": the window's")
      ->capture_default_str()
      ->check(integer_range("--height", 64, 8192));
  add_term(cmd, "--device", opt->device);
  cmd->callback([opt, cmd] {
#if !MSM_TOOL_VIEWER
    (void)opt;
    (void)cmd;
    throw UsageError("this msm was built without the viewer (MSM_BUILD_VIEWER is OFF: GLFW 3.3 or Dear ImGui was "
                     "not found; Debian: libglfw3-dev libimgui-dev); msm render --view FILE renders a view file");
#else
    viewer::ViewerOptions options;
    try {
      if (!opt->view_file.empty()) {
        options.view = viewer::load_view(opt->view_file);
      } else {
        options.view.scene = opt->scene;
        options.view.settings.width = opt->width;
        options.view.settings.height = opt->height;
      }
      if (!opt->technique.empty()) viewer::apply_setting(options.view.settings, "technique", opt->technique);
      options.view.settings.validate();
      if (!opt->script_file.empty()) options.script = viewer::load_script(opt->script_file);
    } catch (const viewer::ViewError& e) { throw UsageError(e.what()); } catch (const viewer::ScriptError& e) {
      throw UsageError(e.what());
    } catch (const render::RenderError& e) { throw UsageError(e.what()); }
    options.device = opt->device;
    try {
      viewer::run_viewer(options);
    } catch (const viewer::ViewerError& e) { throw UsageError(e.what()); } catch (const scene::SceneError& e) {
      throw UsageError(e.what());
    } catch (const render::RenderError& e) { throw UsageError(e.what()); }
#endif
  });
}

} // namespace msm::tool
