// The lights of a view, as the viewer edits them: every light of the scene in the scene's vocabulary
// (scene::DeclaredLight: directional, spot, point), each switched on or off. The panel's "Lights"
// section, the script's light-* actions and the view file's "lights" go through these functions;
// every edit is checked by the scene loader's own rules (scene::parse_light), so an edit the scene
// would refuse is refused with the scene's message. Needs no window system.
#pragma once

#include "msm/scene/scene.h"

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace msm::viewer {

struct ViewLight {
  scene::DeclaredLight light;
  bool on = true;
  scene::LightKind kind() const { return light.kind; }
};

// The scene's lights in the scene's order of kinds: its directional lights (`directional` where
// given, a view's RenderSettings::lights), then its spot and point lights; all on.
std::vector<ViewLight> scene_view_lights(const scene::Scene& scene,
                                         const std::vector<scene::DirectionalLight>& directional);

// A light as a scene's "lights" entry: "type" and the keys of its kind's declaration that it sets
// (no "range" where unbounded, no "angular_height_deg" or "x_axis" where unset).
nlohmann::json light_json(const scene::DeclaredLight& light);
// The same with "on": false for a light switched off (a view file's "lights" entry).
nlohmann::json view_light_json(const ViewLight& light);
// A view file's "lights" entry; ViewError "<where>/<key>: problem" (the scene's message).
ViewLight parse_view_light(const nlohmann::json& entry, const std::string& where);

// `light` with its key set to `value` (JSON null: unset, where the key is optional), checked as a
// scene's light: ViewError "<key>: problem" with the scene's message for a key its kind does not
// declare or a value the scene refuses (an inner cone wider than the outer one, a range <= 0, ...).
scene::DeclaredLight with_light_key(const scene::DeclaredLight& light, std::string_view key,
                                    const nlohmann::json& value);

// A new light of `kind` where the camera looks: a spot light above the camera's target shining
// straight down at it, a point light above the target (both at half the camera's distance to it,
// bright enough for an irradiance of 3 there, their range four times that height), a directional
// light from above the camera's side.
scene::DeclaredLight new_light(scene::LightKind kind, const scene::Camera& camera);

// A spot or point light moved to `position` (a spot keeps its direction); ViewError for a
// directional light (it has no position: set its "towards_light").
scene::DeclaredLight moved_light(const scene::DeclaredLight& light, glm::vec3 position);

// What is drawn: the lights that are on, directional and local.
struct DrawnLights {
  std::vector<scene::DirectionalLight> directional;
  std::vector<scene::LocalLight> local;
};
DrawnLights drawn_lights(const std::vector<ViewLight>& lights);

// Every key a light of some kind declares (the script's light-set checks its KEY against these).
std::vector<std::string> light_keys();

} // namespace msm::viewer
