#include "msm/viewer/lights.h"

#include "msm/viewer/view_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace msm::viewer {
namespace {

using json = nlohmann::json;

json to_json(glm::vec3 v) { return json::array({v.x, v.y, v.z}); }

// The light that `entry` declares, checked by the scene's rules; ViewError with its message, the
// JSON pointer below `where`.
scene::DeclaredLight checked(const json& entry, const std::string& where) {
  try {
    return scene::parse_light(entry.dump(), "light", where);
  } catch (const scene::SceneError& e) { throw ViewError(fmt::format("{}: {}", e.where(), e.problem())); }
}

} // namespace

std::vector<ViewLight> scene_view_lights(const scene::Scene& scene,
                                         const std::vector<scene::DirectionalLight>& directional) {
  std::vector<ViewLight> out;
  for (const scene::DirectionalLight& l : directional.empty() ? scene.lights : directional) {
    out.emplace_back();
    out.back().light.directional = l;
  }
  for (const scene::LocalLight& l : scene.local_lights) {
    out.emplace_back();
    out.back().light.kind = l.kind;
    out.back().light.local = l;
  }
  return out;
}

json light_json(const scene::DeclaredLight& light) {
  json j = {{"type", std::string(scene::light_kind(light.kind).name)}};
  if (light.kind == scene::LightKind::directional) {
    const scene::DirectionalLight& l = light.directional;
    j["towards_light"] = to_json(l.towards_light);
    j["irradiance"] = to_json(l.irradiance);
    j["angular_extent_deg"] = l.angular_extent_deg;
    if (l.angular_height_deg) j["angular_height_deg"] = *l.angular_height_deg;
    if (l.x_axis) j["x_axis"] = to_json(*l.x_axis);
    return j;
  }
  const scene::LocalLight& l = light.local;
  j["position"] = to_json(l.position);
  if (l.spot()) {
    j["direction"] = to_json(l.direction);
    j["inner_cone_deg"] = l.inner_cone_deg;
    j["outer_cone_deg"] = l.outer_cone_deg;
  }
  if (l.range < scene::LocalLight::kInfiniteRange) j["range"] = l.range;
  j["intensity"] = to_json(l.intensity);
  j["radius"] = l.radius;
  return j;
}

json view_light_json(const ViewLight& light) {
  json j = light_json(light.light);
  if (!light.on) j["on"] = false;
  return j;
}

ViewLight parse_view_light(const json& entry, const std::string& where) {
  ViewLight out;
  json light = entry;
  if (light.is_object() && light.contains("on")) {
    if (!light["on"].is_boolean()) throw ViewError(fmt::format("{}/on: expected true or false", where));
    out.on = light["on"].get<bool>();
    light.erase("on");
  }
  out.light = checked(light, where);
  return out;
}

scene::DeclaredLight with_light_key(const scene::DeclaredLight& light, std::string_view key, const json& value) {
  json j = light_json(light);
  if (key == "type") throw ViewError("type: a light keeps its kind (remove it and add another)");
  if (value.is_null())
    j.erase(std::string(key));
  else
    j[std::string(key)] = value;
  return checked(j, "");
}

scene::DeclaredLight new_light(scene::LightKind kind, const scene::Camera& camera) {
  const glm::vec3 up = glm::normalize(camera.up);
  const float height = std::max(0.5f * glm::length(camera.target - camera.position), 1e-3f);
  json j = {{"type", std::string(scene::light_kind(kind).name)}};
  if (kind == scene::LightKind::directional) {
    glm::vec3 side = camera.position - camera.target;
    side -= glm::dot(side, up) * up;
    const float across = glm::length(side);
    j["towards_light"] = to_json(up + (across > 0 ? 0.5f * side / across : glm::vec3(0.0f)));
    return checked(j, "");
  }
  j["position"] = to_json(camera.target + height * up);
  j["range"] = 4.0f * height;
  j["intensity"] = to_json(glm::vec3(3.0f * height * height)); // irradiance 3 at the target
  if (kind == scene::LightKind::spot) {
    j["direction"] = to_json(glm::vec3(0.0f) - up); // not -0 in the files
    j["inner_cone_deg"] = 25.0f;
    j["outer_cone_deg"] = 35.0f;
  }
  return checked(j, "");
}

scene::DeclaredLight moved_light(const scene::DeclaredLight& light, glm::vec3 position) {
  if (light.kind == scene::LightKind::directional)
    throw ViewError("position: a directional light has none (set its towards_light)");
  return with_light_key(light, "position", to_json(position));
}

DrawnLights drawn_lights(const std::vector<ViewLight>& lights) {
  DrawnLights out;
  for (const ViewLight& l : lights) {
    if (!l.on) continue;
    if (l.kind() == scene::LightKind::directional)
      out.directional.push_back(l.light.directional);
    else
      out.local.push_back(l.light.local);
  }
  return out;
}

std::vector<std::string> light_keys() {
  std::vector<std::string> keys;
  for (const scene::LightKindInfo& kind : scene::light_kinds())
    for (std::string_view key : kind.keys)
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.emplace_back(key);
  return keys;
}

} // namespace msm::viewer
