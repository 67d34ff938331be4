#include "render_common.h"
#include "setting_options.h"
#include "vocabulary.h"

#include "msm/image/io.h"
#include "msm/render/settings_schema.h"
#include "msm/techniques.h"
#include "msm/util/limits.h"
#include "msm/util/spelling.h"
#include "msm/viewer/view_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <future>
#include <unistd.h>
#include <vector>

namespace msm::tool {

void add_frame_options(CLI::App* cmd, FrameOptions& o) {
  add_term(cmd, "--scene", o.scene)->capture_default_str();
  add_setting_options(cmd, render::setting_declarations(), o.settings, o.given);
  cmd->get_option("--noise-frame")
      ->description(fmt::format("{} (default: the --frame)", render::find_setting("noise_frame").help))
      ->default_str("");
  // The spellings of older versions.
  for (const auto& [old_name, key] : {std::pair{"--filter", "filter_size"},
                                      {"--sigma", "filter_sigma"},
                                      {"--light-extent", "light_extent_deg"},
                                      {"--light-height", "light_height_deg"}})
    add_deprecated_option(cmd, old_name, render::setting_option_name(render::find_setting(key)), o.given[key]);
  cmd->add_option("--set", o.parameters,
                  "A technique parameter NAME=VALUE, repeatable (msm techniques NAME lists them: type, range, "
                  "default, meaning)")
      ->take_all();
  // The positional vector of older versions: still read for one version, with a warning.
  cmd->add_option("--param", o.params, "")->delimiter(',')->group("");
  add_term(cmd, "--frame", o.animation_frame, ", as msm reference --frame K traces it (default 0)")
      ->check(integer_range("--frame", 0, 9999));
  add_term(cmd, "--device", o.device);
}

void finish_frame_options(FrameOptions& o) {
  if (!o.params.empty()) {
    if (o.params.size() != 4) throw UsageError("--param takes four comma-separated values");
    fmt::print(stderr, "msm: warning: --param is deprecated and goes in the next version: set each parameter by "
                       "name with --set NAME=VALUE (msm techniques NAME lists them)\n");
  }
  apply_given_settings(render::setting_declarations(), o.given, o.settings);
  if (o.given["noise_frame"])
    o.noise_frame = o.settings.frame;
  else
    o.settings.frame = o.animation_frame;
}

scene::Scene scene_at_frame(const FrameOptions& o, scene::Scene scene) {
  if (o.animation_frame == 0) return scene;
  if (!scene.animated())
    throw UsageError(fmt::format("--frame {}: scene '{}' is the same at every frame (no object has a \"motion\"); "
                                 "the blue-noise layer is --noise-frame",
                                 o.animation_frame, scene.name));
  return scene::at_frame(scene, o.animation_frame);
}

render::RenderSettings settings_for(const FrameOptions& options, const std::string& technique) {
  render::RenderSettings s = options.settings;
  s.technique = technique;
  try {
    const Technique& t = render::find_rendered_technique(technique);
    if (s.one_pass && *s.one_pass && (t.formats[0] == TexelFormat::none || t.formats[1] != TexelFormat::none))
      s.one_pass.reset();
  } catch (const render::RenderError&) {
    return s; // validate() reports the unknown name
  }
  const Technique& t = render::find_rendered_technique(technique);
  ParameterValues values = s.parameters; // a view file's, then the command line's
  for (const Parameter* p : t.parameter_list())
    if (!options.params.empty()) values[std::string(p->name)] = options.params[size_t(p->slot)];
  for (const std::string& assignment : options.parameters) {
    try {
      set_parameter(t, values, assignment);
    } catch (const std::invalid_argument& e) {
      throw render::RenderError(fmt::format("{}: --set {}", t.name, e.what()));
    }
  }
  s.parameters = values;
  return s;
}

std::vector<std::string> canonical_technique_names(std::vector<std::string> names) {
  for (std::string& name : names) name = std::string(canonical_technique_name(name));
  return names;
}

void validate_techniques(const FrameOptions& options, const std::vector<std::string>& techniques) {
  for (const std::string& name : techniques) {
    try {
      settings_for(options, name).validate();
    } catch (const render::RenderError& e) { throw UsageError(e.what()); }
  }
}

void check_limits(const FrameOptions& options, const scene::Scene& scene, const std::vector<std::string>& techniques) {
  for (const std::string& name : techniques) {
    try {
      render::check_limits(settings_for(options, name), scene.triangle_count(), scene.lights.size());
    } catch (const limits::LimitError& e) { throw UsageError(fmt::format("{}: {}", scene.source.string(), e.what())); }
  }
}

void check_on_device(const render::Renderer& renderer, const FrameOptions& options,
                     const std::vector<std::string>& techniques) {
  for (const std::string& name : techniques) {
    try {
      renderer.check(settings_for(options, name));
    } catch (const render::RenderError& e) { throw UsageError(e.what()); }
  }
}

std::unique_ptr<vk::Context> open_device(const std::string& device) {
  vk::ContextOptions options;
  options.device = device;
  options.verbose = false;
  try {
    return std::make_unique<vk::Context>(options);
  } catch (const std::exception& e) { throw UsageError(fmt::format("no usable Vulkan device: {}", e.what())); }
}

scene::Scene load_scene_or_fail(const std::string& name_or_path) {
  try {
    return scene::load_scene(name_or_path);
  } catch (const scene::SceneError& e) { throw UsageError(e.what()); }
}

void ensure_output_dir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw UsageError(
        fmt::format("{}: cannot create the output directory: {}", dir.string(), ec ? ec.message() : "not a directory"));
  if (access(dir.c_str(), W_OK) != 0)
    throw UsageError(fmt::format("{}: the output directory is not writable", dir.string()));
}

void check_output_dir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::path existing = dir.empty() ? "." : dir;
  while (!std::filesystem::exists(existing, ec) && existing.has_relative_path())
    existing = existing.has_parent_path() && existing.parent_path() != existing ? existing.parent_path() : ".";
  if (!std::filesystem::is_directory(existing, ec))
    throw UsageError(
        fmt::format("{}: cannot create the output directory: {} is not a directory", dir.string(), existing.string()));
  if (access(existing.c_str(), W_OK) != 0)
    throw UsageError(existing == dir ? fmt::format("{}: the output directory is not writable", dir.string())
                                     : fmt::format("{}: cannot create the output directory: {} is not writable",
                                                   dir.string(), existing.string()));
}

nlohmann::json render_json(const render::RenderSettings& s, const scene::Scene& scene, int frame,
                           const std::vector<std::string>& warnings, const vk::Context& ctx,
                           const render::RenderResult& result) {
  const Technique& t = render::find_rendered_technique(s.technique);
  nlohmann::json passes = nlohmann::json::object();
  for (const render::PassTime& pass : result.passes) passes[pass.name] = pass.ms;
  nlohmann::json out = {{"scene", scene.name},
                        {"scene_source", scene.source.string()},
                        {"description", t.description},
                        {"bits_per_texel", t.bits_per_texel}};
  // Every setting under its key (msm/render/settings_schema.h), then what the technique's
  // defaults resolved to.
  out.update(render::settings_json(s));
  const bool one_pass = s.one_pass.value_or(t.one_pass_default());
  out["resolved"] = {{"depth_bias", s.resolved_depth_bias()},
                     {"soft_kernel", s.resolved_soft_kernel()},
                     {"lookup", s.lookup != render::RenderSettings::Lookup::automatic ? out["lookup"]
                                : t.nonlinear()                                       ? "dither"
                                                                                      : "bilinear"},
                     {"filter_mode", one_pass ? "one-pass" : "three-pass"},
                     {"cascades", render::resolved_cascades(s, scene)},
                     {"light_extent_deg", s.light_extent_deg     ? nlohmann::json(*s.light_extent_deg)
                                          : scene.lights.empty() ? nlohmann::json() // spot or point lights only
                                                                 : nlohmann::json(scene.light().angular_extent_deg)}};
  // The view file of this render: msm render --view takes this JSON and renders the same again.
  viewer::View view;
  view.scene = scene.source.string().starts_with("builtin:") ? scene.name : scene.source.string();
  view.camera = scene.camera;
  view.settings = s;
  view.object_frame = frame;
  // Spot and point lights (a scene's, or a view's in place of the scene's): every light, with its type.
  if (!scene.local_lights.empty() || scene.lights.empty()) view.lights = viewer::scene_view_lights(scene, s.lights);
  out["view"] = viewer::view_json(view);
  out["frame"] = frame;                             // the animated objects' frame (the view's object_frame)
  std::vector<std::string> all_warnings = warnings; // the scene's, then the render's own
  all_warnings.insert(all_warnings.end(), result.warnings.begin(), result.warnings.end());
  out["warnings"] = all_warnings;
  out["device"] = ctx.info().describe();
  out["gpu_ms"] = passes;
  out["gpu_ms_total"] = result.total_ms;
  return out;
}

void write_render(const std::filesystem::path& dir, const std::string& stem, const render::RenderResult& result,
                  const nlohmann::json& json) {
  image::FileSet files;
  write_render(files, dir, stem, result, json);
  try {
    files.commit();
  } catch (const image::ImageError& e) { throw UsageError(e.what()); }
}

void write_render(image::FileSet& files, const std::filesystem::path& dir, const std::string& stem,
                  const render::RenderResult& result, const nlohmann::json& json) {
  try {
    // The EXRs (zlib: most of the output's work) are encoded on a second thread while this one
    // encodes the PNG (image output was 16% of a one-shot 1080p render). The files are
    // added in the same order as before.
    const std::filesystem::path exr = dir / (stem + ".exr"), rgb = dir / (stem + "-rgb.exr"),
                                scattering = dir / (stem + "-scattering.exr");
    auto exrs = std::async(std::launch::async, [&] {
      std::array<std::vector<std::uint8_t>, 3> bytes;
      bytes[0] = image::encode_exr(exr, result.shadow);
      if (!result.shadow_rgb.empty()) bytes[1] = image::encode_exr(rgb, result.shadow_rgb);
      if (!result.scattering.empty()) bytes[2] = image::encode_exr(scattering, result.scattering);
      return bytes;
    });
    // The PNG from the sRGB target's bytes themselves (no float encode; the same file as
    // encode_png of `color`, the bytes decoded: ImageTest.Png8FromSrgbBytesEqualsTheFloatPath).
    const std::filesystem::path png_path = dir / (stem + ".png");
    std::vector<std::uint8_t> png =
        result.color_srgb8.empty()
            ? image::encode_png(png_path, result.color)
            : image::encode_png8(png_path, result.color.width(), result.color.height(), 3, result.color_srgb8);
    const std::array<std::vector<std::uint8_t>, 3> exr_bytes = exrs.get(); // rethrows its ImageError
    files.add(png_path, png);
    files.add(exr, exr_bytes[0]);
    if (!result.shadow_rgb.empty())
      files.add(rgb, exr_bytes[1]);
    else
      files.remove(rgb);            // no stale copy of an earlier coloured render
    if (!result.scattering.empty()) // scattering techniques: in-scattered radiance, visible fraction
      files.add(scattering, exr_bytes[2]);
    else
      files.remove(scattering);
    std::string text = json.dump(2) + "\n";
    files.add(dir / (stem + ".json"), std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  } catch (const image::ImageError& e) { throw UsageError(e.what()); }
}

} // namespace msm::tool
