// What the rendering subcommands (render, bench, demo) share: the options of a frame, the
// device, the scene, and writing a render's outputs.
#pragma once

#include "commands.h"
#include "msm/image/io.h"
#include "msm/render/renderer.h"
#include "msm/vk/context.h"
#include "setting_options.h"
#include "usage.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace msm::tool {

struct FrameOptions {
  render::RenderSettings settings;
  std::string scene = "fence";         // built-in name or scene file
  std::string device;                  // see ContextOptions::device; empty: MSM_DEVICE or the first GPU
  std::vector<std::string> parameters; // --set NAME=VALUE, for each technique
  std::vector<float> params;           // the deprecated --param x,y,z,w
  // --frame: the frame of a dynamic scene (scene::at_frame: its animated objects moved), as msm
  // reference --frame traces it. --noise-frame: the blue-noise layer and offset
  // (RenderSettings::frame); unset, the animation frame's, so that a sequence varies.
  int animation_frame = 0;
  std::optional<int> noise_frame;
  // The text of each declared setting given on the command line (msm/render/settings_schema.h), by
  // key; finish_frame_options applies them to `settings`.
  GivenSettings given;
};

// --scene, an option for each declared setting of msm/render/settings_schema.h (--width, --msaa,
// --filter-size, --no-mipmaps, --lookup, ...: --KEY-WITH-DASHES, a flag that is on by default as
// --no-KEY), --set, --frame, --device; the help shows each one's default from options.settings.
void add_frame_options(CLI::App* cmd, FrameOptions& options);
// Applies the parsed options to options.settings; UsageError for bad values.
void finish_frame_options(FrameOptions& options);

// The scene at --frame (scene::at_frame; the scene itself at frame 0); UsageError where the frame
// is not 0 and every frame of the scene is the same.
scene::Scene scene_at_frame(const FrameOptions& options, scene::Scene scene);

// The frame settings for one technique: --filter-mode one-pass applies to the techniques with one
// moment image (the depth-based ones and 6MSM keep their own pipeline).
render::RenderSettings settings_for(const FrameOptions& options, const std::string& technique);

// The table's names for technique names and aliases (msm = msm-hamburger-64, ...): outputs and
// tables are named by the table's name whichever was typed.
std::vector<std::string> canonical_technique_names(std::vector<std::string> names);

// Every technique's settings are valid, before anything is loaded or created (UsageError naming
// the first problem otherwise).
void validate_techniques(const FrameOptions& options, const std::vector<std::string>& techniques);

// The scene's triangles and every technique's memory estimate are within the limits shared with
// msm reference (msm/util/limits.h), before the device or the output exists: UsageError naming the
// scene, the value and the limit otherwise.
void check_limits(const FrameOptions& options, const scene::Scene& scene, const std::vector<std::string>& techniques);

// The device can render every technique's settings (Renderer::check), before any output exists:
// UsageError naming the first problem (an MSAA count the device lacks, an image too large).
void check_on_device(const render::Renderer& renderer, const FrameOptions& options,
                     const std::vector<std::string>& techniques);

// The Vulkan context (validation with MSM_VALIDATION=1); a failure is a UsageError naming devices.
std::unique_ptr<vk::Context> open_device(const std::string& device);
// A built-in scene or a scene file; SceneError becomes a UsageError with the loader's message.
scene::Scene load_scene_or_fail(const std::string& name_or_path);

// Creates the directory (UsageError if impossible or not writable).
void ensure_output_dir(const std::filesystem::path& dir);
// What ensure_output_dir would refuse, creating nothing: the directory, or where it does not exist
// yet its nearest existing parent, must be a writable directory. For commands that create the
// directory only once they have something to put in it.
void check_output_dir(const std::filesystem::path& dir);

// Every setting of a render (technique parameters included), the scene's frame (--frame) and the
// warnings printed for it (scene::shadow_framing_warnings) followed by the render's own
// (RenderResult::warnings), and its pass times.
nlohmann::json render_json(const render::RenderSettings& settings, const scene::Scene& scene, int frame,
                           const std::vector<std::string>& warnings, const vk::Context& ctx,
                           const render::RenderResult& result);

// <dir>/<stem>.png (sRGB colour), <dir>/<stem>.exr (shadow buffer), <dir>/<stem>-rgb.exr (coloured
// shadows only), <dir>/<stem>.json: all or none (image::FileSet: temporaries, then renamed together).
void write_render(const std::filesystem::path& dir, const std::string& stem, const render::RenderResult& result,
                  const nlohmann::json& json);
// The same files added to a set the caller commits (with other renders': all of them or none).
void write_render(image::FileSet& files, const std::filesystem::path& dir, const std::string& stem,
                  const render::RenderResult& result, const nlohmann::json& json);

} // namespace msm::tool
