// `msm reference`: ground truth of a scene's shadows by CPU ray tracing (msm::reference): writes
// DIR/visibility.exr (the shadow buffer), DIR/radiance.exr, DIR/surface.exr (n_dot_l and object
// index, masks for comparisons), for --effect scattering DIR/scattering.exr (the in-scattered radiance
// and the ray length), for --effect environment DIR/irradiance.exr (E and its standard error),
// and DIR/reference.json (settings, timings, sample count), all or
// none (msm::image::FileSet). Bad input is a UsageError (exit status 2); scene
// errors (SceneError) name the file and the problem.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "msm/image/io.h"
#include "msm/reference/reference.h"
#include "msm/reference/settings_schema.h"
#include "msm/scene/scene.h"
#include "msm/shading.h"
#include "msm/util/clock.h"
#include "msm/util/limits.h"
#include "msm/util/output_dir.h"
#include "msm/util/progress.h"
#include "reference_look.h"
#include "reference_options.h"
#include "setting_options.h"
#include "usage.h"
#include "vocabulary.h"

namespace msm::tool {
namespace {

namespace fs = std::filesystem;
using msm::reference::Settings;

// The light as traced, the scene's as declared and the command line's overrides of it (each given
// one; none: the scene's light exactly).
nlohmann::ordered_json light_json(const msm::scene::DirectionalLight& declared, const Settings& settings,
                                  const msm::reference::Result& result) {
  nlohmann::ordered_json overrides = nlohmann::ordered_json::object();
  if (settings.light_shape) overrides["shape"] = std::string(msm::reference::to_string(*settings.light_shape));
  if (settings.light_extent_deg) overrides["extent_deg"] = *settings.light_extent_deg;
  if (settings.light_width_deg) overrides["width_deg"] = *settings.light_width_deg;
  if (settings.light_height_deg) overrides["height_deg"] = *settings.light_height_deg;
  nlohmann::ordered_json scene_light = {{"shape", declared.rectangular() ? "rectangle" : "disc"},
                                        {"extent_deg", declared.angular_extent_deg}};
  if (declared.angular_height_deg) scene_light["height_deg"] = *declared.angular_height_deg;
  return {{"shape", std::string(msm::reference::to_string(result.light_shape))},
          {"extent_deg", result.light_extent_deg},
          {"width_deg", result.light_width_deg},
          {"height_deg", result.light_height_deg},
          {"scene", scene_light},
          {"overrides", overrides}};
}

} // namespace

void add_reference_options(CLI::App* cmd, ReferenceOptions& o) {
  add_term(cmd, "--scene", o.scene, " (default fence)");
  add_setting_options(cmd, msm::reference::setting_declarations(), Settings{}, o.given);
  cmd->get_option("--effect")->required()->default_str("");
  // The spellings of older versions.
  add_deprecated_option(cmd, "--light-extent", "--light-extent-deg", o.given["light_extent_deg"]);
  add_deprecated_option(cmd, "--light-width", "--light-width-deg", o.given["light_width_deg"]);
  add_deprecated_option(cmd, "--light-height", "--light-height-deg", o.given["light_height_deg"]);
  add_deprecated_flag(cmd, "--probe-lights", "--extracted-lights", o.deprecated_probe_lights);
  add_term(cmd, "--probe", o.probe,
           ": lights the scene instead of its own lights (image-based lighting; the scene's probe settings are "
           "kept, else 32 lights, 128² per face), as msm render --probe");
  add_term(cmd, "--lights", o.lights, " (default: the scene's)");
  add_term(cmd, "--sub-lights", o.sub_lights, " (default: the scene's); --extracted-lights traces them");
  add_term(cmd, "--frame", o.frame,
           ", traced as msm render --frames draws it, its probe turned K times --probe-rotation-speed")
      ->check(integer_range("--frame", 0, 9999));
  add_term(cmd, "--probe-rotation-speed", o.probe_rotation_speed, " (with --frame)");
  add_term(cmd, "--threads", o.threads, " (default 0: all cores)");
  add_term(cmd, "--out", o.out, " (default out/reference)");
  add_term_flag(cmd, "--json", o.json, ": reference.json");
  add_term_flag(cmd, "--progress", o.progress);
}

Settings reference_settings(ReferenceOptions& o) {
  if (o.deprecated_probe_lights) o.given["extracted_lights"] = "true";
  Settings settings;
  apply_given_settings(msm::reference::setting_declarations(), o.given, settings);
  settings.threads = o.threads;
  if (settings.probe_lights && settings.effect != msm::reference::Effect::environment)
    throw UsageError("--extracted-lights applies to --effect environment only");
  if (settings.light_shape == msm::reference::LightShape::disc &&
      (settings.light_width_deg || settings.light_height_deg))
    throw UsageError("--light-width-deg / --light-height-deg make a rectangle: they cannot go with --light-shape disc");
  try {
    msm::reference::validate(settings);
  } catch (const std::invalid_argument& e) { throw UsageError(e.what()); }
  return settings;
}

namespace {

// The scene as traced: its probe (--probe, turned to --frame), its animated objects at --frame, its
// probe's light count; UsageError where the effect needs what the scene lacks.
msm::scene::Scene reference_scene(const ReferenceOptions& o, const CLI::App& cmd, const Settings& settings) {
  msm::scene::Scene scene = msm::scene::load_scene(o.scene); // SceneError: printed by main
  if (!o.probe.empty()) try {
      msm::scene::set_probe(scene, o.probe);
    } catch (const msm::scene::SceneError& e) { throw UsageError(e.what()); }
  if (o.probe_rotation_speed != 0.0f) {
    if (!scene.probe)
      throw UsageError(
          fmt::format("--probe-rotation-speed: scene '{}' has no light probe (its \"probe\" key)", scene.name));
    if (cmd.count("--frame") == 0) throw UsageError("--probe-rotation-speed turns the probe per --frame: give one");
    // The probe's lights are cut again at the turned probe (below), as msm render's device does.
    scene.probe->rotation_deg += float(o.frame) * o.probe_rotation_speed;
  }
  if (o.frame > 0) {
    if (!scene.animated() && o.probe_rotation_speed == 0.0f)
      throw UsageError(fmt::format("--frame {}: scene '{}' is the same at every frame (no object has a "
                                   "\"motion\", no --probe-rotation-speed)",
                                   o.frame, scene.name));
    scene = msm::scene::at_frame(scene, o.frame);
  }
  if (o.lights || o.sub_lights || o.probe_rotation_speed != 0.0f) try {
      msm::scene::set_probe_light_count(scene, o.lights.value_or(scene.probe ? scene.probe->lights : 1), o.sub_lights);
    } catch (const msm::scene::SceneError& e) { throw UsageError(e.what()); }
  if (settings.effect == msm::reference::Effect::scattering && !scene.medium)
    throw UsageError(fmt::format("{}: --effect scattering needs a scene with a \"medium\" (extinction, "
                                 "scattering_albedo, phase; scenes/README.md)",
                                 scene.source.string()));
  if (settings.effect == msm::reference::Effect::environment && !scene.probe)
    throw UsageError(fmt::format("{}: --effect environment needs a scene with a \"probe\" (file, lights, intensity, "
                                 "rotation_deg, size; scenes/README.md)",
                                 scene.source.string()));
  return scene;
}

// A progress bar on a terminal (or with --progress), else a line per tenth once the run takes long.
void report_progress(Settings& settings, bool bar_wanted) {
  auto bar = [](const msm::reference::Progress& p) {
    fmt::print(stderr, "\r{}", util::progress_bar("msm reference", p.rows_done, p.rows_total, p.seconds, 40));
    if (p.rows_done == p.rows_total) fmt::print(stderr, "\n");
    std::fflush(stderr);
  };
  if (bar_wanted || ::isatty(::fileno(stderr))) {
    settings.progress = bar;
  } else {
    // A log (stderr redirected): a line per tenth once the run has taken a few seconds.
    settings.progress = [lines = std::make_shared<msm::util::ProgressLines>("msm reference: ", " rows")](
                            const msm::reference::Progress& p) {
      if (auto line = lines->next(p.rows_done, p.rows_total, p.seconds)) fmt::print(stderr, "{}\n", *line);
    };
  }
}

// The images of a result; no stale copy of an earlier run's other effects.
void add_reference_images(msm::image::FileSet& files, const fs::path& out, const msm::reference::Result& result) {
  try {
    files.add_exr(out / "visibility.exr", result.visibility);
    files.add_exr(out / "radiance.exr", result.radiance);
    files.add_exr(out / "surface.exr", result.surface);
    // translucent: the transmittance per RGB channel (coloured shadows); no stale copy
    // from an earlier run into the same folder for the other effects.
    if (!result.visibility_rgb.empty())
      files.add_exr(out / "visibility_rgb.exr", result.visibility_rgb);
    else
      files.remove(out / "visibility_rgb.exr");
    if (!result.scattering.empty())
      files.add_exr(out / "scattering.exr", result.scattering);
    else
      files.remove(out / "scattering.exr");
    if (!result.irradiance.empty()) {
      files.add_exr(out / "irradiance.exr", result.irradiance);
      // environment: the renderer's look (ACES at exposure 1, the probe where no surface is), to
      // compare with msm render's PNG (msm compare radiance.png TECHNIQUE.png).
      files.add_png(out / "radiance.png", reference_look(result, 1.0f));
    } else {
      files.remove(out / "irradiance.exr");
      files.remove(out / "radiance.png");
    }
  } catch (const msm::image::ImageError& e) { throw UsageError(e.what()); }
}

// reference.json but its timings: the settings as traced, the light, the files and their channels.
nlohmann::ordered_json reference_json(const msm::scene::Scene& scene, const Settings& settings, int frame,
                                      const std::vector<std::string>& warnings, const msm::reference::Result& result) {
  nlohmann::ordered_json j;
  j["scene"] = {{"name", scene.name}, {"source", scene.source.string()}, {"triangles", scene.triangle_count()}};
  // Every declared setting under its key (msm/reference/settings_schema.h), as render.json has
  // its own; those msm render has too under the render settings' keys.
  j.update(msm::reference::settings_json(settings));
  j["frame"] = frame;
  j["samples_per_pixel"] = result.samples; // as traced: 1 for hard and translucent
  if (!scene.lights.empty()) j["light"] = light_json(scene.light(), settings, result);
  for (const msm::scene::LightKindInfo& kind : msm::scene::light_kinds())
    j["light_counts"][std::string(kind.name)] = scene.light_count(kind.kind);
  j["warnings"] = warnings;
  j["threads"] = result.threads;
  j["rays"] = result.rays;
  j["background_pixels"] = result.background_pixels;
  j["mean_visibility"] = result.mean_visibility;
  j["files"] = {{"visibility", "visibility.exr"}, {"radiance", "radiance.exr"}, {"surface", "surface.exr"}};
  j["channels"] = {{"visibility", result.visibility.channel_names()},
                   {"radiance", result.radiance.channel_names()},
                   {"surface", result.surface.channel_names()}};
  if (!result.scattering.empty()) {
    j["files"]["scattering"] = "scattering.exr";
    j["channels"]["scattering"] = result.scattering.channel_names();
    j["medium"] = {{"extinction", scene.medium->extinction},
                   {"scattering_albedo", scene.medium->scattering_albedo},
                   {"g", scene.medium->g}};
  }
  if (!result.irradiance.empty()) {
    j["files"]["irradiance"] = "irradiance.exr";
    j["files"]["radiance_png"] = "radiance.png";
    j["channels"]["irradiance"] = result.irradiance.channel_names();
    const msm::scene::ProbeLighting& p = *scene.probe;
    j["probe"] = {{"file", p.file.string()},
                  {"lights", p.lights},
                  {"intensity", p.intensity},
                  {"rotation_deg", p.rotation_deg},
                  {"size", p.size},
                  {"probe_lights", settings.probe_lights},
                  {"horizon_split", p.horizon_split},
                  {"sub_lights", p.sub_lights}};
  }
  if (!result.visibility_rgb.empty()) {
    j["files"]["visibility_rgb"] = "visibility_rgb.exr";
    j["channels"]["visibility_rgb"] = result.visibility_rgb.channel_names();
  }
  return j;
}

} // namespace

void add_reference(CLI::App& app) {
  auto opt = std::make_shared<ReferenceOptions>();
  auto* cmd = app.add_subcommand("reference", "Ground-truth shadows of a scene by CPU ray tracing (Embree): "
                                              "visibility.exr, radiance.exr, reference.json");
  add_reference_options(cmd, *opt);
  cmd->callback([opt, cmd] {
    const auto start = std::chrono::steady_clock::now();
    Settings settings = reference_settings(*opt);
    msm::scene::Scene scene = reference_scene(*opt, *cmd, settings);
    // The filtered effect traces the renderer's shadow map: the warnings of its framing.
    std::vector<std::string> warnings;
    if (settings.effect == msm::reference::Effect::filtered)
      warnings = msm::scene::shadow_framing_warnings(scene, settings.width, settings.height, settings.shadow_size);
    for (const std::string& w : warnings) fmt::print(stderr, "msm reference: {}\n", w);
    // The same limits as msm render's, before the output directory or anything large exists.
    try {
      msm::reference::check_limits(settings, scene.triangle_count());
    } catch (const msm::limits::LimitError& e) {
      throw UsageError(fmt::format("{}: {}", scene.source.string(), e.what()));
    }
    const double load_seconds = util::seconds_since(start);
    const fs::path out = opt->out;
    if (const auto problem = util::prepare_output_dir(out, "msm-reference-probe"))
      throw UsageError(fmt::format("--out {}: {}", out.string(), *problem));
    report_progress(settings, opt->progress);

    msm::reference::Result result;
    try {
      result = msm::reference::render(scene, settings);
    } catch (const std::invalid_argument& e) {
      throw UsageError(fmt::format("{}: {}", scene.source.string(), e.what()));
    }
    const auto write_start = std::chrono::steady_clock::now();
    // All the files or none (a full disk, a failed rename): temporaries first, renamed together.
    msm::image::FileSet files;
    add_reference_images(files, out, result);
    nlohmann::ordered_json j = reference_json(scene, settings, opt->frame, warnings, result);
    j["seconds"] = {{"load", load_seconds},
                    {"build", result.build_seconds},
                    {"render", result.render_seconds},
                    {"write_images", util::seconds_since(write_start)},
                    {"total", util::seconds_since(start)}};
    const std::string text = j.dump(2) + "\n";
    try {
      files.add(out / "reference.json", {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
      files.commit();
    } catch (const msm::image::ImageError& e) { throw UsageError(e.what()); }
    if (opt->json)
      fmt::print("{}", text);
    else
      fmt::print("msm reference: {} {} {}x{}, {} spp: mean visibility {:.4f}, {:.2f} s ({} rays) -> {}\n", scene.name,
                 msm::reference::to_string(settings.effect), settings.width, settings.height, result.samples,
                 result.mean_visibility, result.render_seconds, result.rays, out.string());
  });
}

} // namespace msm::tool
