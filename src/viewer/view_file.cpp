#include "msm/viewer/view_file.h"

#include "msm/render/settings_schema.h"
#include "msm/techniques.h"
#include "msm/util/spelling.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace msm::viewer {
namespace {

using json = nlohmann::json;

[[noreturn]] void fail(std::string_view key, std::string_view problem) {
  throw ViewError(fmt::format("{}: {}", key, problem));
}

float number(std::string_view key, const json& v) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) fail(key, fmt::format("expected a number, got {}", v.dump()));
  return v.get<float>();
}

int integer(std::string_view key, const json& v) {
  if (!v.is_number_integer() || v.get<long long>() < -(1ll << 30) || v.get<long long>() > (1ll << 30))
    fail(key, fmt::format("expected an integer, got {}", v.dump()));
  return v.get<int>();
}

std::string word(std::string_view key, const json& v) {
  if (!v.is_string()) fail(key, fmt::format("expected a string, got {}", v.dump()));
  return v.get<std::string>();
}

glm::vec3 vec3(std::string_view key, const json& v) {
  if (!v.is_array() || v.size() != 3) fail(key, fmt::format("expected [x, y, z], got {}", v.dump()));
  return {number(key, v[0]), number(key, v[1]), number(key, v[2])};
}

json to_json(glm::vec3 v) { return json::array({v.x, v.y, v.z}); }

// Rejects keys of an object that are not in `known`.
void check_keys(const json& object, std::string_view where, std::initializer_list<std::string_view> known) {
  if (!object.is_object()) fail(where, fmt::format("expected an object, got {}", object.dump()));
  for (const auto& [key, value] : object.items())
    if (std::find(known.begin(), known.end(), key) == known.end())
      fail(fmt::format("{}/{}", where, key), "unknown key");
}

} // namespace

std::vector<std::string> setting_keys() { return render::setting_keys(); }

void apply_setting(render::RenderSettings& s, std::string_view key, const json& v) {
  if (key == "params") // the positional vector of older versions
    fail(key, "replaced by \"parameters\", each by name (msm techniques NAME lists them)");
  try {
    render::apply_setting(s, render::find_setting(key), v);
  } catch (const render::SettingError& e) { fail(fmt::format("{}{}", key, e.pointer), e.what()); }
}

json setting_json(const render::RenderSettings& s, std::string_view key) {
  try {
    return render::find_setting(key).get(s);
  } catch (const render::SettingError& e) { fail(key, e.what()); }
}

View default_view(const std::string& scene_name, const scene::Scene& scene) {
  View v;
  v.scene = scene_name;
  v.camera = scene.camera;
  return v;
}

json view_json(const View& v) {
  const json settings = render::settings_json(v.settings);
  json lights = json::array();
  if (v.lights) {
    for (const ViewLight& l : *v.lights) lights.push_back(view_light_json(l));
  } else {
    for (const scene::DirectionalLight& l : v.settings.lights) {
      scene::DeclaredLight declared;
      declared.directional = l;
      json light = light_json(declared);
      light.erase("type"); // the default
      lights.push_back(light);
    }
  }
  json out = {{"msm_view", 1}, {"scene", v.scene}};
  if (v.camera)
    out["camera"] = {{"position", to_json(v.camera->position)},
                     {"target", to_json(v.camera->target)},
                     {"up", to_json(v.camera->up)},
                     {"fov_y_deg", v.camera->fov_y_deg},
                     {"near", v.camera->near},
                     {"far", v.camera->far}};
  out["settings"] = settings;
  if (!lights.empty()) out["lights"] = lights;
  if (v.object_frame > 0) out["object_frame"] = v.object_frame;
  return out;
}

View parse_view(std::string_view text, const std::filesystem::path& file) {
  const std::string name = file.string();
  json j;
  try {
    j = json::parse(text, nullptr, true, true);
  } catch (const json::parse_error& e) { throw ViewError(fmt::format("{}: malformed JSON: {}", name, e.what())); }
  // A render's JSON output holds its view under "view" (msm render --view renders it again).
  if (j.is_object() && !j.contains("msm_view") && j.contains("view") && j["view"].is_object()) j = json(j["view"]);
  try {
    check_keys(j, "", {"msm_view", "scene", "camera", "lights", "settings", "object_frame"});
    if (!j.contains("msm_view") || j["msm_view"] != 1) fail("/msm_view", "required, and only version 1 exists");
    View v;
    if (j.contains("scene")) {
      v.scene = word("/scene", j["scene"]);
      const std::vector<std::string> builtins = scene::builtin_scene_names();
      bool builtin = std::find(builtins.begin(), builtins.end(), v.scene) != builtins.end();
      if (!builtin && std::filesystem::path(v.scene).is_relative())
        v.scene = (file.parent_path() / v.scene).lexically_normal().string();
    }
    if (j.contains("camera")) {
      const json& c = j["camera"];
      scene::Camera camera;
      check_keys(c, "/camera", {"position", "target", "up", "fov_y_deg", "near", "far"});
      if (c.contains("position")) camera.position = vec3("/camera/position", c["position"]);
      if (c.contains("target")) camera.target = vec3("/camera/target", c["target"]);
      if (c.contains("up")) camera.up = vec3("/camera/up", c["up"]);
      if (c.contains("fov_y_deg")) camera.fov_y_deg = number("/camera/fov_y_deg", c["fov_y_deg"]);
      if (c.contains("near")) camera.near = number("/camera/near", c["near"]);
      if (c.contains("far")) camera.far = number("/camera/far", c["far"]);
      if (!(camera.fov_y_deg > 0 && camera.fov_y_deg < 180)) fail("/camera/fov_y_deg", "outside (0, 180)");
      if (!(camera.near >= scene::kMinCameraNear && camera.near < camera.far && camera.far <= scene::kMaxCameraFar))
        fail("/camera/near", "expected 1e-6 <= near < far <= 1e9");
      if (!(glm::length(camera.position - camera.target) > 0)) fail("/camera/target", "equals the position");
      if (!(glm::length(glm::cross(camera.target - camera.position, camera.up)) > 0))
        fail("/camera/up", "parallel to the view direction");
      v.camera = camera;
    }
    if (j.contains("lights")) {
      const json& lights = j["lights"];
      if (!lights.is_array() || lights.empty() || lights.size() > size_t(scene::kMaxLights))
        fail("/lights", fmt::format("expected an array of 1 to {} lights", scene::kMaxLights));
      std::vector<ViewLight> lights_read;
      for (size_t i = 0; i < lights.size(); ++i)
        lights_read.push_back(parse_view_light(lights[i], fmt::format("/lights/{}", i)));
      // Entries with their "type" (the viewer's) are every light of the view; without, directional
      // lights in place of the scene's directional ones (the older files and msm render's --light).
      if (std::any_of(lights.begin(), lights.end(), [](const json& l) { return l.contains("type"); }))
        v.lights = lights_read;
      v.settings.lights = drawn_lights(lights_read).directional;
    }
    if (j.contains("object_frame")) {
      v.object_frame = integer("/object_frame", j["object_frame"]);
      if (v.object_frame < 0 || v.object_frame > kMaxObjectFrame)
        fail("/object_frame", fmt::format("expected 0 to {}", kMaxObjectFrame));
    }
    if (j.contains("settings")) {
      const json& s = j["settings"];
      if (!s.is_object()) fail("/settings", "expected an object");
      // The technique first: the parameters are its own.
      std::vector<std::pair<std::string, json>> items;
      if (s.contains("technique")) items.emplace_back("technique", s["technique"]);
      for (const auto& [key, value] : s.items())
        if (key != "technique") items.emplace_back(key, value);
      for (const auto& [key, value] : items) {
        try {
          apply_setting(v.settings, key, value);
        } catch (const ViewError& e) { throw ViewError(fmt::format("/settings/{}", e.what())); }
      }
      try {
        v.settings.validate();
      } catch (const render::RenderError& e) { fail("/settings", e.what()); }
    }
    return v;
  } catch (const ViewError& e) { throw ViewError(fmt::format("{}: {}", name, e.what())); }
}

View load_view(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ViewError(fmt::format("{}: cannot open the view file", file.string()));
  std::stringstream text;
  text << in.rdbuf();
  return parse_view(text.str(), file);
}

void save_view(const std::filesystem::path& file, const View& view) {
  View v = view;
  const std::vector<std::string> builtins = scene::builtin_scene_names();
  if (std::find(builtins.begin(), builtins.end(), v.scene) == builtins.end())
    v.scene = std::filesystem::absolute(v.scene).lexically_normal().string();
  std::string text = view_json(v).dump(2) + "\n";
  std::filesystem::path tmp = file;
  tmp += fmt::format(".tmp{}", ::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw ViewError(fmt::format("{}: cannot write the view file", file.string()));
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw ViewError(fmt::format("{}: cannot write the view file: {}", file.string(), ec.message()));
  }
}

void apply_view_lights(const std::vector<ViewLight>& lights, scene::Scene& scene) {
  DrawnLights drawn = drawn_lights(lights);
  scene.lights = std::move(drawn.directional);
  scene.local_lights = std::move(drawn.local);
}

scene::Scene load_view_scene(const View& view) {
  scene::Scene s = scene::load_scene(view.scene);
  if (view.lights) apply_view_lights(*view.lights, s);
  if (view.object_frame > 0) s = scene::at_frame(s, view.object_frame);
  if (view.camera) s.camera = *view.camera;
  return s;
}

std::string render_command(const std::filesystem::path& view_file, const std::string& out_dir) {
  return fmt::format("msm render --view '{}' -o '{}'", view_file.string(), out_dir);
}

} // namespace msm::viewer
