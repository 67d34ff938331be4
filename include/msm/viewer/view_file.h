// A view: the scene, camera, lights and every render setting of one frame, as JSON. The viewer
// saves and loads it, its script's `set KEY VALUE` goes through the same setters, and
// `msm render --view FILE` renders exactly that frame. Needs no window system.
//
// {
//   "msm_view": 1,                                  REQUIRED format version
//   "scene": "fence",                               built-in name or scene file (relative: to the view file)
//   "camera": {"position": [x,y,z], "target": [x,y,z], "up": [0,1,0], "fov_y_deg": 45, "near": 0.1, "far": 1000},
//   "lights": [{"towards_light": [x,y,z], "irradiance": [r,g,b], "angular_extent_deg": 0}],  absent: the scene's
//             every light of the view, in place of all the scene's: entries of a scene file's "lights"
//             (scene.h: "type" directional (the default), spot or point, and that kind's keys; a
//             rectangular light also "angular_height_deg": h, "x_axis": [x,y,z]), each with
//             "on": false where switched off (msm/viewer/lights.h). Where no entry has a "type",
//             directional lights in place of the scene's directional ones only (its spot and point
//             lights kept)
//   "settings": {"technique": "msm-hamburger-64", "width": 1280, ...}   the keys of setting_keys()
//   "object_frame": 0                               the frame of the scene's animated objects
//                                                   (scene::at_frame), 0..100000; written when > 0
// }
// Every key is optional but msm_view; unknown keys are errors naming the key (ViewError).
#pragma once

#include "msm/render/renderer.h"
#include "msm/scene/scene.h"
#include "msm/viewer/lights.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace msm::viewer {

class ViewError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct View {
  std::string scene = "fence";         // as given (built-in name or path)
  std::optional<scene::Camera> camera; // empty: the scene's
  render::RenderSettings settings;     // its lights: the directional ones of `lights` that are on
  // Every light of the view, on and off, in place of the scene's: "lights" (none: the scene's, and
  // settings.lights replaces its directional ones where given).
  std::optional<std::vector<ViewLight>> lights;
  int object_frame = 0; // the animated objects at this frame (scene::at_frame)
};
inline constexpr int kMaxObjectFrame = 100000;

// The keys of "settings": the declared settings (msm/render/settings_schema.h).
std::vector<std::string> setting_keys();
// Sets one setting from JSON (a bare word where a string is expected also comes as a string).
// ViewError "KEY: expected ..." for a value of the wrong type or range, "KEY: unknown setting (did
// you mean ...?)" for an unknown key.
void apply_setting(render::RenderSettings& settings, std::string_view key, const nlohmann::json& value);
nlohmann::json setting_json(const render::RenderSettings& settings, std::string_view key);

// A view of a scene as it comes (its camera and lights, default settings).
View default_view(const std::string& scene_name, const scene::Scene& scene);

nlohmann::json view_json(const View& view);
// ViewError "<file>: <key>: problem" (or the JSON parser's message with its position).
View parse_view(std::string_view text, const std::filesystem::path& file);
View load_view(const std::filesystem::path& file);
// Written atomically (a temporary, then renamed); ViewError when it cannot be written.
void save_view(const std::filesystem::path& file, const View& view);

// A view's lights that are on (View::lights) in place of all of `scene`'s.
void apply_view_lights(const std::vector<ViewLight>& lights, scene::Scene& scene);

// Loads the view's scene (SceneError passes through) with the view's camera and its objects at the
// view's object_frame: with view.settings, what `msm render --view` and the viewer render.
scene::Scene load_view_scene(const View& view);

// The `msm render` line that renders a view file (the viewer's "copy the command").
std::string render_command(const std::filesystem::path& view_file, const std::string& out_dir = "msm-render");

} // namespace msm::viewer
