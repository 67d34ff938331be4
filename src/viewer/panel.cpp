// The viewer's panel, camera fly and script actions: each control and each action calls the same
// setter, so a script exercises what the panel does.
#include "setting_controls.h"
#include "viewer_state.h"

#include "msm/render/settings_schema.h"
#include "msm/vk/context.h"
#include "msm/vk/swapchain.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <utility>

namespace msm::viewer {
namespace {

double number(const std::string& text) {
  double v = 0;
  std::from_chars(text.data(), text.data() + text.size(), v); // checked by parse_script
  return v;
}

// A combo over string choices; true when the selection changed.
bool choose(const char* label, std::string& value, const std::vector<std::string>& choices) {
  bool changed = false;
  if (ImGui::BeginCombo(label, value.c_str())) {
    for (const std::string& c : choices) {
      bool selected = c == value;
      if (ImGui::Selectable(c.c_str(), selected) && !selected) {
        value = c;
        changed = true;
      }
      if (selected) ImGui::SetItemDefaultFocus();
    }
    ImGui::EndCombo();
  }
  return changed;
}

std::vector<std::string> technique_names() {
  std::vector<std::string> out;
  for (const Technique* t : render::rendered_techniques()) out.emplace_back(t->name);
  return out;
}

// A setting through the view file's setter (the one `set KEY VALUE` uses).
void set(render::RenderSettings& s, const char* key, const nlohmann::json& value) { apply_setting(s, key, value); }

// A number or integer setting's slider over its control's range (an integer kept on its steps).
bool setting_slider(const SettingControl& c, const char* label, nlohmann::json& value) {
  const ImGuiSliderFlags flags = c.logarithmic ? ImGuiSliderFlags_Logarithmic : ImGuiSliderFlags_None;
  if (c.setting->type == SettingType::integer) {
    int v = value.get<int>();
    if (!ImGui::SliderInt(label, &v, int(c.min), int(c.max), "%d", flags)) return false;
    value = int(c.min) + (v - int(c.min)) / c.step * c.step;
    return true;
  }
  float v = value.get<float>();
  if (!ImGui::SliderFloat(label, &v, float(c.min), float(c.max), "%.3g", flags)) return false;
  value = v;
  return true;
}

// A plain setting's control (setting_controls.h): a checkbox, a combo over its declared choices, a
// slider, or for a nullable number a checkbox for its own value (from the resolved default) and
// its slider; the declaration's meaning and range as the tooltip. The value goes through the view
// file's setter, checked against the declaration.
void setting_control(render::RenderSettings& s, const SettingControl& c) {
  const render::SettingDeclaration& setting = *c.setting;
  nlohmann::json value = setting.get(s);
  bool changed = false;
  ImGui::BeginDisabled(!c.enabled);
  switch (c.kind) {
  case ControlKind::checkbox: {
    bool on = value.get<bool>();
    changed = ImGui::Checkbox(c.label.c_str(), &on);
    value = on;
    break;
  }
  case ControlKind::combo: {
    std::string text = value.is_string() ? value.get<std::string>() : value.dump();
    if ((changed =
             choose(c.label.c_str(), text, std::vector<std::string>(setting.choices.begin(), setting.choices.end()))))
      value = setting.type == SettingType::integer ? nlohmann::json(std::stoi(text)) : nlohmann::json(text);
    break;
  }
  case ControlKind::slider: changed = setting_slider(c, c.label.c_str(), value); break;
  case ControlKind::optional: {
    bool own = !value.is_null();
    if (ImGui::Checkbox(own ? fmt::format("##own {}", c.label).c_str() : c.label.c_str(), &own)) {
      value = own ? nlohmann::json(optional_start(s, c)) : nlohmann::json();
      changed = true;
    }
    if (own && !value.is_null()) {
      ImGui::SameLine();
      changed |= setting_slider(c, c.label.c_str(), value);
    }
    break;
  }
  default: break;
  }
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("%s (%s)", std::string(setting.help).c_str(), render::setting_range_text(setting).c_str());
  if (changed) set(s, std::string(setting.key).c_str(), value);
}

// One widget per declared parameter of the technique (msm/cpu/techniques.h), its meaning as the
// tooltip; a value outside the declared range is not set.
void technique_parameters(render::RenderSettings& s, const Technique& t) {
  for (const Parameter* p : t.parameter_list()) {
    const std::string label(p->name);
    float value = s.parameter(p->name);
    bool changed = false;
    switch (p->type) {
    case ParameterType::choice: {
      std::string choice = p->value_text(value);
      std::vector<std::string> names;
      for (const ParameterChoice& c : p->choices) names.emplace_back(c.name);
      if (choose(label.c_str(), choice, names)) value = p->parse(choice), changed = true;
      break;
    }
    case ParameterType::flag: {
      bool on = value != 0.0f;
      if (ImGui::Checkbox(label.c_str(), &on)) value = on ? 1.0f : 0.0f, changed = true;
      break;
    }
    case ParameterType::integer: {
      int v = int(value);
      if (ImGui::InputInt(label.c_str(), &v)) value = float(v), changed = true;
      break;
    }
    case ParameterType::number: changed = ImGui::InputFloat(label.c_str(), &value, 0.0f, 0.0f, "%.3g"); break;
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s (%s)", std::string(p->meaning).c_str(), p->range_text().c_str());
    if (changed && p->accepts(value)) s.set_parameter(p->name, value);
  }
}

} // namespace

glm::vec3 Viewer::light_direction() const {
  for (const ViewLight& l : light_list())
    if (l.on && l.kind() == scene::LightKind::directional) return l.light.directional.towards_light;
  return {0.0f, 1.0f, 0.0f};
}

void Viewer::set_light_direction(glm::vec3 towards) {
  if (!view.lights) { // the scene's lights: its directional ones through the settings
    if (view.settings.lights.empty()) view.settings.lights = scene.lights;
    if (!view.settings.lights.empty()) view.settings.lights.front().towards_light = glm::normalize(towards);
    return;
  }
  std::vector<ViewLight> next = *view.lights;
  for (ViewLight& l : next)
    if (l.on && l.kind() == scene::LightKind::directional) {
      l.light.directional.towards_light = glm::normalize(towards);
      set_lights(std::move(next));
      return;
    }
}

std::vector<ViewLight> Viewer::light_list() const {
  return view.lights ? *view.lights : scene_view_lights(scene, view.settings.lights);
}

bool Viewer::set_lights(std::vector<ViewLight> next) {
  const DrawnLights drawn = drawn_lights(next), before = drawn_lights(light_list());
  try {
    left->set_lights(drawn.directional, drawn.local);
    render::RenderSettings s = view.settings;
    s.lights = drawn.directional;
    left->check(s);
    if (right) right->set_lights(drawn.directional, drawn.local); // a refusal there ends the split
  } catch (const render::RenderError& e) {
    left->set_lights(before.directional, before.local); // drawn until now
    if (right) right->set_lights(before.directional, before.local);
    report_error(e.what());
    return false;
  }
  view.lights = std::move(next);
  view.settings.lights = good_settings.lights = drawn.directional;
  error.clear();
  return true;
}

void Viewer::reset_lights() {
  view.lights.reset();
  view.settings.lights.clear();
  good_settings.lights.clear();
  selected_light = -1;
  left->set_lights(scene.lights, scene.local_lights);
  if (right) right->set_lights(scene.lights, scene.local_lights);
}

void Viewer::report_error(const std::string& message) {
  error = message;
  note(script ? fmt::format("{}: error: {}", script_where, message) : "error: " + message);
}

void Viewer::show_object_frame(int frame) {
  view.object_frame = std::clamp(frame, 0, kMaxObjectFrame);
  if (!scene.animated()) return;
  MSM_VK_CHECK(vkDeviceWaitIdle(ctx->device())); // the buffers are uploaded again
  const scene::Scene moved = scene::at_frame(scene, view.object_frame);
  left->move_objects(moved);
  if (right) right->move_objects(moved);
}

void Viewer::set_technique(const std::string& name) {
  std::string canonical(canonical_technique_name(name));
  if (canonical == view.settings.technique) return;
  set(view.settings, "technique", canonical);
  view.settings.reset_parameters(); // another technique's parameters mean something else
  // Front- and back-face averaged depth (Kneiphof §4.2.3) is for the soft techniques only
  // (RenderSettings::validate): off for any other, which would refuse it.
  if (!render::find_rendered_technique(view.settings.technique).soft()) view.settings.front_back_depth = false;
}

void Viewer::set_split(const std::string& name) {
  split_technique = name.empty() ? "" : std::string(canonical_technique_name(name));
  if (!split_technique.empty()) render::find_rendered_technique(split_technique);
}

bool Viewer::set_scene(const std::string& name, bool keep_view) {
  scene::Scene loaded = scene::load_scene(name);
  // The new scene's renderer first: one the renderer refuses (its lights, or the view's settings
  // with them) leaves the viewer with the scene and renderers it had.
  render::RenderSettings settings = view.settings;
  if (!keep_view || view.lights) settings.lights.clear(); // the scene's own lights
  std::unique_ptr<render::Renderer> renderer;
  try {
    renderer = std::make_unique<render::Renderer>(*ctx, loaded);
    renderer->check(settings);
  } catch (const render::RenderError& e) {
    report_error(fmt::format("{}: {} (the viewer keeps {})", name, e.what(), view.scene));
    return false;
  }
  MSM_VK_CHECK(vkDeviceWaitIdle(ctx->device()));
  right.reset();
  left = std::move(renderer);
  scene = std::move(loaded);
  view.scene = name;
  view.settings.lights = good_settings.lights = settings.lights;
  view.lights.reset();
  selected_light = -1;
  if (!keep_view) {
    view.camera = scene.camera;
    view.object_frame = 0;
    animate_objects = false;
  }
  show_object_frame(view.object_frame);
  std::error_code ec;
  scene_time.reset();
  if (std::filesystem::is_regular_file(name, ec)) scene_time = std::filesystem::last_write_time(name, ec);
  note(fmt::format("scene: {} ({} triangles)", name, scene.triangle_count()));
  return true;
}

void Viewer::reload_if_changed() {
  auto now = std::chrono::steady_clock::now();
  if (!scene_time || now - scene_checked < std::chrono::seconds(1)) return;
  scene_checked = now;
  std::error_code ec;
  auto time = std::filesystem::last_write_time(view.scene, ec);
  if (ec || time == *scene_time) return;
  try {
    if (set_scene(view.scene, true)) error.clear();
  } catch (const scene::SceneError& e) { error = e.what(); }
  scene_time = time; // a refusal is reported once; the next save is tried again
}

void Viewer::save_view_file(const std::string& path) {
  save_view(path, view);
  note(fmt::format("view saved: {}", path));
}

void Viewer::copy_command() {
  save_view_file(view_path);
  std::string command = render_command(view_path);
  glfwSetClipboardString(window, command.c_str());
  note(command);
}

void Viewer::fly(float dt) {
  ImGuiIO& io = ImGui::GetIO();
  scene::Camera& c = *view.camera;
  glm::vec3 up = glm::normalize(c.up);
  glm::vec3 forward = c.target - c.position;
  float distance = glm::length(forward);
  forward /= distance;
  glm::vec3 right = glm::normalize(glm::cross(forward, up));
  if (!io.WantCaptureMouse && ImGui::IsMouseDragging(ImGuiMouseButton_Right, 0.0f)) {
    ImVec2 d = io.MouseDelta;
    float yaw = -d.x * 0.005f, pitch = -d.y * 0.005f;
    float elevation = std::asin(std::clamp(glm::dot(forward, up), -1.0f, 1.0f));
    pitch = std::clamp(elevation + pitch, -1.5f, 1.5f) - elevation;
    forward = std::cos(yaw) * forward + std::sin(yaw) * glm::cross(up, forward) +
              (1.0f - std::cos(yaw)) * glm::dot(up, forward) * up;
    right = glm::normalize(glm::cross(forward, up));
    forward = std::cos(pitch) * forward + std::sin(pitch) * glm::cross(right, forward);
    c.target = c.position + distance * glm::normalize(forward);
  }
  if (!io.WantCaptureKeyboard) {
    glm::vec3 move(0.0f);
    if (ImGui::IsKeyDown(GLFW_KEY_W)) move += forward;
    if (ImGui::IsKeyDown(GLFW_KEY_S)) move -= forward;
    if (ImGui::IsKeyDown(GLFW_KEY_D)) move += right;
    if (ImGui::IsKeyDown(GLFW_KEY_A)) move -= right;
    if (ImGui::IsKeyDown(GLFW_KEY_E)) move += up;
    if (ImGui::IsKeyDown(GLFW_KEY_Q)) move -= up;
    if (glm::length(move) > 0) {
      float speed = fly_speed * (io.KeyShift ? 4.0f : 1.0f);
      glm::vec3 step = glm::normalize(move) * speed * dt;
      c.position += step;
      c.target += step;
    }
  }
  if (!io.WantCaptureMouse && ImGui::IsMouseDragging(ImGuiMouseButton_Middle, 0.0f)) {
    // The light turns with the mouse: azimuth across, elevation up and down (kept above the horizon).
    glm::vec3 t = light_direction();
    float azimuth = std::atan2(t.z, t.x) + io.MouseDelta.x * 0.01f;
    float elevation = std::clamp(std::asin(std::clamp(t.y, -1.0f, 1.0f)) - io.MouseDelta.y * 0.01f, 0.02f, 1.5707f);
    set_light_direction(
        {std::cos(elevation) * std::cos(azimuth), std::sin(elevation), std::cos(elevation) * std::sin(azimuth)});
  }
  move_selected_light(dt);
  if (animate_objects && scene.animated()) {
    object_clock += double(object_rate) * double(dt);
    if (int(object_clock) != view.object_frame) show_object_frame(int(object_clock));
  }
  if (animate_light) {
    glm::vec3 t = light_direction();
    float a = glm::radians(light_speed_deg) * dt;
    set_light_direction({std::cos(a) * t.x - std::sin(a) * t.z, t.y, std::sin(a) * t.x + std::cos(a) * t.z});
  }
  // The split-screen divider: dragged outside the panel.
  if (!split_technique.empty() || (show_truth && truth_image)) {
    const char* right_name = show_truth && truth_image ? "error against the ground truth" : split_technique.c_str();
    float w = io.DisplaySize.x, x = divider * w;
    bool near = std::abs(io.MousePos.x - x) < 6.0f && !io.WantCaptureMouse;
    if (near && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) dragging_divider = true;
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) dragging_divider = false;
    if (dragging_divider) divider = std::clamp(io.MousePos.x / w, 0.02f, 0.98f);
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    ImU32 colour = near || dragging_divider ? IM_COL32(255, 255, 255, 255) : IM_COL32(200, 200, 200, 200);
    draw->AddLine(ImVec2(x, 0), ImVec2(x, io.DisplaySize.y), colour, 2.0f);
    draw->AddText(ImVec2(x - 8 - ImGui::CalcTextSize(view.settings.technique.c_str()).x, io.DisplaySize.y - 24),
                  IM_COL32_WHITE, view.settings.technique.c_str());
    draw->AddText(ImVec2(x + 8, io.DisplaySize.y - 24), IM_COL32_WHITE, right_name);
  }
}

// The scene, the technique and the split screen's second technique.
void Viewer::choices_section() {
  std::string scene_name = view.scene;
  std::vector<std::string> scenes = scene::builtin_scene_names();
  if (std::find(scenes.begin(), scenes.end(), scene_name) == scenes.end()) scenes.push_back(scene_name);
  if (choose("scene", scene_name, scenes)) try {
      set_scene(scene_name, false);
    } catch (const scene::SceneError& e) { error = e.what(); }
  ImGui::SameLine();
  if (ImGui::Button("reload")) try {
      set_scene(view.scene, true);
    } catch (const scene::SceneError& e) { error = e.what(); }
  std::string technique = view.settings.technique;
  if (choose("technique", technique, technique_names())) {
    set_technique(technique);
    error.clear();
  }
  bool split = !split_technique.empty();
  if (ImGui::Checkbox("split screen", &split)) set_split(split ? "pcf" : "");
  if (split) {
    std::string other = split_technique;
    if (choose("right side", other, technique_names())) set_split(other);
    ImGui::SliderFloat("divider", &divider, 0.02f, 0.98f);
  }
}

// Every declared render setting's control (setting_controls.h), in the table's order: the
// technique's parameters, its shadow map, filter and bias, the shading's settings and its light.
void Viewer::technique_settings_section() {
  render::RenderSettings& s = view.settings;
  const Technique& t = render::find_rendered_technique(s.technique);
  for (const SettingControl& c : setting_controls(t)) {
    switch (c.kind) {
    case ControlKind::technique: break; // choices_section
    case ControlKind::parameters: technique_parameters(s, t); break;
    case ControlKind::window_size:
      if (c.setting->key == "width") ImGui::TextDisabled("image %dx%d: the window's size", s.width, s.height);
      break;
    case ControlKind::light:
      if (c.enabled && c.setting->key == "light_extent_deg") light_shape_controls(s, c);
      break;
    default: setting_control(s, c);
    }
  }
}

// A disc: one extent. A rectangle (the scene light's own, or made one here): its width along the
// light frame's x axis and its height (RenderSettings::light_height_deg), each its own slider over
// the declared control range.
void Viewer::light_shape_controls(render::RenderSettings& s, const SettingControl& c) {
  const scene::DirectionalLight drawn = scene::overridden_light(scene.light(), s.light_extent_deg, s.light_height_deg);
  float extent = drawn.angular_extent_deg;
  bool rectangle = drawn.rectangular();
  float height = drawn.angular_height_deg.value_or(extent);
  if (ImGui::Checkbox("rectangular light", &rectangle)) {
    s.light_extent_deg = extent;
    if (rectangle)
      s.light_height_deg = height;
    else
      s.light_height_deg.reset();
  }
  if (ImGui::SliderFloat(rectangle ? "light width deg" : "light extent deg", &extent, float(c.min), float(c.max))) {
    s.light_extent_deg = extent;
    if (rectangle) s.light_height_deg = height;
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", std::string(c.setting->help).c_str());
  const render::SettingDeclaration& h = render::find_setting("light_height_deg");
  const auto [height_min, height_max] = render::setting_control_range(h);
  if (rectangle && ImGui::SliderFloat("light height deg", &height, float(height_min), float(height_max))) {
    s.light_extent_deg = extent;
    s.light_height_deg = height;
  }
  if (rectangle && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", std::string(h.help).c_str());
}

// The light's direction and animation, the objects' animation and the camera's fly speed.
void Viewer::light_and_camera_section() {
  glm::vec3 t = light_direction();
  float azimuth = glm::degrees(std::atan2(t.z, t.x)), elevation = glm::degrees(std::asin(std::clamp(t.y, -1.f, 1.f)));
  bool a = ImGui::SliderFloat("light azimuth", &azimuth, -180.0f, 180.0f);
  bool e = ImGui::SliderFloat("light elevation", &elevation, 1.0f, 90.0f);
  if (a || e) {
    float az = glm::radians(azimuth), el = glm::radians(elevation);
    set_light_direction({std::cos(el) * std::cos(az), std::sin(el), std::cos(el) * std::sin(az)});
  }
  ImGui::Checkbox("animate light", &animate_light);
  ImGui::SameLine();
  ImGui::SliderFloat("deg/s", &light_speed_deg, -90.0f, 90.0f);
  if (scene.animated()) { // the scene's objects with a "motion"
    if (ImGui::Checkbox("animate objects", &animate_objects)) object_clock = view.object_frame;
    ImGui::SameLine();
    ImGui::SliderFloat("frames/s", &object_rate, 1.0f, 60.0f);
    int frame = view.object_frame;
    if (ImGui::InputInt("object frame", &frame)) {
      show_object_frame(frame);
      object_clock = view.object_frame;
    }
  }
  ImGui::SliderFloat("fly speed", &fly_speed, 0.05f, 50.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
  ImGui::TextDisabled("WASD/QE move, right drag looks, wheel: speed;");
  ImGui::TextDisabled("middle drag turns the light");
  if (ImGui::Button("reset camera and light")) {
    view.camera = scene.camera;
    reset_lights();
  }
}

// One widget per key of the light's kind (scene::light_kinds(): its declaration's keys, the scene's
// ranges through with_light_key): numbers and [x, y, z] dragged, an unset key typed as JSON. The
// edited light, or nothing; ViewError for a value the scene refuses.
static std::optional<scene::DeclaredLight> light_key_widgets(const scene::DeclaredLight& light) {
  const nlohmann::json j = light_json(light);
  std::optional<scene::DeclaredLight> edited;
  for (std::string_view name : scene::light_kind(light.kind).keys) {
    const std::string key(name);
    const nlohmann::json value = j.contains(key) ? j[key] : nlohmann::json();
    if (value.is_array() && value.size() == 3) {
      float v[3] = {value[0].get<float>(), value[1].get<float>(), value[2].get<float>()};
      if (ImGui::DragFloat3(key.c_str(), v, 0.01f)) edited = with_light_key(light, key, {v[0], v[1], v[2]});
    } else if (value.is_number()) {
      float v = value.get<float>();
      if (ImGui::DragFloat(key.c_str(), &v, 0.05f)) edited = with_light_key(light, key, v);
    } else {
      char text[64] = "";
      if (ImGui::InputTextWithHint(key.c_str(), "unset (a JSON value)", text, sizeof text,
                                   ImGuiInputTextFlags_EnterReturnsTrue))
        edited = with_light_key(light, key, setting_value(text));
    }
  }
  return edited;
}

// The view's lights by number and kind, each switched on or off, removed, selected (its keys
// below, moved by the arrow keys); a light of each kind added where the camera looks.
void Viewer::lights_section() {
  const std::vector<ViewLight> lights = light_list();
  std::optional<std::vector<ViewLight>> next;
  if (selected_light >= int(lights.size())) selected_light = -1;
  try {
    for (size_t i = 0; i < lights.size(); ++i) {
      ImGui::PushID(int(i));
      bool on = lights[i].on;
      if (ImGui::Checkbox("##on", &on)) (next = lights)->at(i).on = on;
      ImGui::SameLine();
      const std::string label = fmt::format("{} {}", i, scene::light_kind(lights[i].kind()).name);
      if (ImGui::Selectable(label.c_str(), selected_light == int(i), 0, ImVec2(ImGui::CalcItemWidth() * 0.6f, 0)))
        selected_light = selected_light == int(i) ? -1 : int(i);
      ImGui::SameLine();
      if (ImGui::SmallButton("remove")) {
        next = lights;
        next->erase(next->begin() + std::ptrdiff_t(i));
        selected_light = -1;
      }
      ImGui::PopID();
    }
    for (const scene::LightKindInfo& kind : scene::light_kinds()) {
      if (kind.kind != scene::light_kinds().front().kind) ImGui::SameLine();
      if (ImGui::Button(fmt::format("add {}", kind.name).c_str())) {
        next = lights;
        next->push_back({new_light(kind.kind, *view.camera), true});
        selected_light = int(next->size()) - 1;
      }
    }
    if (!next && selected_light >= 0) {
      ImGui::Separator();
      ImGui::Text("light %d", selected_light);
      if (std::optional<scene::DeclaredLight> edited = light_key_widgets(lights[size_t(selected_light)].light))
        (next = lights)->at(size_t(selected_light)).light = *edited;
      ImGui::TextDisabled("arrows or Ctrl+drag move it across the view,");
      ImGui::TextDisabled("PgUp/PgDn along it");
    }
  } catch (const ViewError& e) { report_error(fmt::format("light {}: {}", selected_light, e.what())); }
  if (next) set_lights(std::move(*next));
}

// The time of each pass of the last frame and the history of the total.
void Viewer::gpu_time_section() {
  double total = 0;
  for (const render::PassTime& p : passes) {
    ImGui::Text("%-16s %8.3f ms", p.name.c_str(), p.ms);
    total += p.ms;
  }
  ImGui::Text("%-16s %8.3f ms", "total", total);
  float top = *std::max_element(gpu_history.begin(), gpu_history.end());
  ImGui::PlotLines("##history", gpu_history.data(), int(gpu_history.size()), int(history_next), nullptr, 0.0f,
                   top * 1.1f + 1e-3f, ImVec2(0, 50));
  if (!frame_ms.empty()) ImGui::Text("frame %.1f ms (wall)", frame_ms.back());
}

// The ray-traced view and the errors of the technique against it.
void Viewer::ground_truth_section() {
  ImGui::SliderInt("samples", &truth_samples, 1, 256, "%d", ImGuiSliderFlags_Logarithmic);
  if (truth.running()) {
    ImGui::ProgressBar(truth.progress(), ImVec2(-1, 0));
  } else if (ImGui::Button("ray trace this view")) {
    start_truth(truth_samples);
  }
  if (!truth.error().empty()) ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "%s", truth.error().c_str());
  if (truth_metrics) {
    const scene::Camera& c = *view.camera;
    if (c.position != truth_camera.position || c.target != truth_camera.target)
      ImGui::TextColored(ImVec4(1, 0.8f, 0.3f, 1), "of an earlier view (the camera moved)");
    ImGui::Text("%s: MAE %.4f", truth_technique.c_str(), truth_metrics->mae);
    ImGui::Text("leaking %.4f, over-darkening %.4f", truth_metrics->light_leaking, truth_metrics->over_darkening);
    ImGui::Checkbox("error image right of the divider", &show_truth);
    if (show_truth) ImGui::TextDisabled("red: too bright (leaking), blue: too dark");
  }
}

// Screenshots, view files and the command that renders the view.
void Viewer::files_section() {
  if (ImGui::Button("screenshot")) screenshot_path = fmt::format("msm-view-{}.png", ++screenshot_count);
  char path[512];
  std::snprintf(path, sizeof path, "%s", view_path.c_str());
  if (ImGui::InputText("view file", path, sizeof path)) view_path = path;
  if (ImGui::Button("save view")) try {
      save_view_file(view_path);
    } catch (const ViewError& e) { error = e.what(); }
  ImGui::SameLine();
  if (ImGui::Button("load view")) try {
      View loaded = load_view(view_path);
      if (loaded.camera) view.camera = loaded.camera;
      reset_lights();
      view.settings = loaded.settings;
      if (loaded.lights) set_lights(*loaded.lights);
      show_object_frame(loaded.object_frame);
    } catch (const ViewError& e) { error = e.what(); }
  ImGui::SameLine();
  if (ImGui::Button("copy the command")) try {
      copy_command();
    } catch (const ViewError& e) { error = e.what(); }
}

void Viewer::panel() {
  ImGuiIO& io = ImGui::GetIO();
  PanelLayout layout = panel_layout(io.DisplaySize.x, io.DisplaySize.y);
  // Collapsed when the window becomes small (and at the start in a small one), opened when it
  // becomes large; the user's click holds in between.
  if (layout.collapsed != small_window) {
    small_window = layout.collapsed;
    ImGui::SetNextWindowCollapsed(layout.collapsed);
  }
  if (collapse_panel) ImGui::SetNextWindowCollapsed(*std::exchange(collapse_panel, std::nullopt));
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(layout.width, io.DisplaySize.y));
  ImGui::SetNextWindowBgAlpha(0.85f);
  // The title says where an error is when the panel is collapsed ("###": the same window).
  std::string title = error.empty() ? "msm view###panel" : "msm view: error (open the panel)###panel";
  bool open = ImGui::Begin(title.c_str(), nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize);
  panel_min = ImGui::GetWindowPos();
  panel_max = ImVec2(panel_min.x + ImGui::GetWindowSize().x, panel_min.y + ImGui::GetWindowSize().y);
  if (!open) { // collapsed: the title bar only
    ImGui::End();
    return;
  }
  ImGui::PushItemWidth(kPanelWidgetShare * layout.width);
  render::RenderSettings& s = view.settings;
  ImGui::Text("%s, %d triangles, %dx%d", scene.name.c_str(), int(scene.triangle_count()), s.width, s.height);
  if (!error.empty()) ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "%s", error.c_str());

  choices_section();
  if (ImGui::CollapsingHeader("Technique settings", ImGuiTreeNodeFlags_DefaultOpen)) technique_settings_section();
  if (ImGui::CollapsingHeader("Light and camera")) light_and_camera_section();
  if (ImGui::CollapsingHeader("Lights")) lights_section();
  ImGui::Checkbox("moment map in the corner", &show_map);
  if (ImGui::CollapsingHeader("GPU time", ImGuiTreeNodeFlags_DefaultOpen)) gpu_time_section();
  if (ImGui::CollapsingHeader("Ground truth", ImGuiTreeNodeFlags_DefaultOpen)) ground_truth_section();
  if (ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) files_section();
  if (!status.empty()) ImGui::TextWrapped("%s", status.c_str());
  ImGui::PopItemWidth();
  ImGui::End();
}

// The selected spot or point light moves in the camera's plane (arrows) and along its view (PgUp,
// PgDn) at the fly speed, four times with shift; or follows the mouse across the view while the
// left button drags it with Ctrl held.
void Viewer::move_selected_light(float dt) {
  ImGuiIO& io = ImGui::GetIO();
  if (selected_light < 0) return;
  std::vector<ViewLight> next = light_list();
  if (selected_light >= int(next.size()) || next[size_t(selected_light)].kind() == scene::LightKind::directional)
    return;
  const ViewLight light = next[size_t(selected_light)];
  const scene::Camera& c = *view.camera;
  const glm::vec3 forward = glm::normalize(c.target - c.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, c.up)), up = glm::cross(right, forward);
  glm::vec3 move(0.0f), step(0.0f);
  if (!io.WantCaptureKeyboard) {
    if (ImGui::IsKeyDown(GLFW_KEY_RIGHT)) move += right;
    if (ImGui::IsKeyDown(GLFW_KEY_LEFT)) move -= right;
    if (ImGui::IsKeyDown(GLFW_KEY_UP)) move += up;
    if (ImGui::IsKeyDown(GLFW_KEY_DOWN)) move -= up;
    if (ImGui::IsKeyDown(GLFW_KEY_PAGE_UP)) move += forward;
    if (ImGui::IsKeyDown(GLFW_KEY_PAGE_DOWN)) move -= forward;
  }
  if (glm::length(move) > 0) step = glm::normalize(move) * fly_speed * (io.KeyShift ? 4.0f : 1.0f) * dt;
  if (!io.WantCaptureMouse && io.KeyCtrl && ImGui::IsMouseDragging(ImGuiMouseButton_Left, 0.0f)) {
    // A pixel's size at the light's distance along the view: the light stays under the cursor.
    const float depth = std::max(glm::dot(light.light.local.position - c.position, forward), c.near);
    const float pixel = 2.0f * depth * std::tan(glm::radians(c.fov_y_deg) / 2.0f) / io.DisplaySize.y;
    step += pixel * (io.MouseDelta.x * right - io.MouseDelta.y * up);
  }
  if (!(glm::length(step) > 0)) return;
  try {
    next[size_t(selected_light)].light = moved_light(light.light, light.light.local.position + step);
  } catch (const ViewError& e) {
    report_error(fmt::format("light {}: {}", selected_light, e.what()));
    return;
  }
  set_lights(std::move(next));
}

// A light-* action of the script (script.h): what the panel's Lights section does. A light the
// scene or the renderer refuses is reported, the lights kept.
void Viewer::light_action(const Action& a) {
  const std::vector<std::string>& x = a.args;
  std::vector<ViewLight> next = light_list();
  if (a.verb == "light-add") {
    if (next.size() >= size_t(scene::kMaxLights))
      return report_error(fmt::format("light-add: the view has {} lights, the most a scene holds", next.size()));
    const scene::LightKind kind = *scene::parse_light_kind(x[0]);
    next.push_back({new_light(kind, *view.camera), true});
    if (set_lights(next)) {
      selected_light = int(next.size()) - 1;
      note(fmt::format("light {}: {} added: {}", next.size() - 1, x[0], light_json(next.back().light).dump()));
    }
    return;
  }
  const size_t n = size_t(number(x[0]));
  if (n >= next.size())
    return report_error(fmt::format("{} {}: the view has {} lights (numbered from 0)", a.verb, n, next.size()));
  try {
    if (a.verb == "light-remove") {
      next.erase(next.begin() + std::ptrdiff_t(n));
    } else if (a.verb == "light-on" || a.verb == "light-off") {
      next[n].on = a.verb == "light-on";
    } else if (a.verb == "light-move") {
      next[n].light = moved_light(next[n].light, glm::vec3(number(x[1]), number(x[2]), number(x[3])));
    } else if (a.verb == "light-set") {
      next[n].light = with_light_key(next[n].light, x[1], setting_value(x[2]));
    }
  } catch (const ViewError& e) { return report_error(fmt::format("light {}: {}", n, e.what())); }
  if (!set_lights(next)) return;
  if (a.verb == "light-remove")
    note(fmt::format("light {}: removed", n));
  else
    note(fmt::format("light {}: {}{}", n, view_light_json(next[n]).dump(), next[n].on ? "" : " (off)"));
}

void Viewer::step_script() {
  if (wait_frames > 0) {
    --wait_frames;
    return;
  }
  if (pending_resize) {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window, &w, &h);
    VkExtent2D e = swapchain->extent();
    if (w == pending_resize->first && h == pending_resize->second && int(e.width) == w && int(e.height) == h) {
      note(fmt::format("resize: {}x{}, swapchain recreated (generation {})", w, h, swapchain->generation()));
      pending_resize.reset();
    } else if (++resize_tries > 300) {
      throw ViewerError(
          fmt::format("{}: the window stayed {}x{} (swapchain {}x{})", script_where, w, h, e.width, e.height));
    }
    return;
  }
  if (script_next >= script->size()) return; // done: the window stays for the user
  const Action& a = (*script)[script_next++];
  script_where = a.where;
  const std::vector<std::string>& x = a.args;
  try {
    if (a.verb == "technique") {
      set_technique(x[0]);
      note(fmt::format("technique: {}", view.settings.technique));
    } else if (a.verb == "each-technique") {
      // One frame of each, in the table's order (each action runs before a frame).
      for (const std::string& name : technique_names())
        script->insert(script->begin() + std::ptrdiff_t(script_next), Action{"technique", {name}, a.line, a.where});
    } else if (a.verb == "set") {
      apply_setting(view.settings, x[0], setting_value(x[1]));
      note(fmt::format("set {} = {}", x[0], setting_json(view.settings, x[0]).dump()));
    } else if (a.verb == "camera") {
      view.camera->position = glm::vec3(number(x[0]), number(x[1]), number(x[2]));
      view.camera->target = glm::vec3(number(x[3]), number(x[4]), number(x[5]));
    } else if (a.verb == "light") {
      set_light_direction(glm::vec3(number(x[0]), number(x[1]), number(x[2])));
    } else if (a.verb == "split") {
      set_split(x[0] == "off" ? "" : x[0]);
    } else if (a.verb == "divider") {
      divider = float(number(x[0]));
    } else if (a.verb == "load-view") {
      View loaded = load_view(x[0]);
      if (loaded.scene != view.scene)
        throw ViewerError(
            fmt::format("{}: {} shows scene '{}', the viewer '{}'", a.where, x[0], loaded.scene, view.scene));
      if (loaded.camera) view.camera = loaded.camera;
      reset_lights();
      view.settings = loaded.settings;
      if (loaded.lights) set_lights(*loaded.lights);
      show_object_frame(loaded.object_frame);
      if (loaded.settings.width != int(swapchain->extent().width) ||
          loaded.settings.height != int(swapchain->extent().height)) {
        glfwSetWindowSize(window, loaded.settings.width, loaded.settings.height);
        pending_resize = {loaded.settings.width, loaded.settings.height};
        resize_tries = 0;
      }
    } else if (a.verb == "save-view") {
      save_view_file(x[0]);
    } else if (a.verb == "screenshot") {
      screenshot_path = x[0];
    } else if (a.verb == "panel-mask") {
      write_panel_mask(x[0]);
    } else if (a.verb == "panel") {
      collapse_panel = x[0] == "collapsed";
      note(fmt::format("panel: {}", x[0]));
    } else if (a.verb == "resize") {
      int w = int(number(x[0])), h = int(number(x[1]));
      glfwSetWindowSize(window, w, h);
      pending_resize = {w, h};
      resize_tries = 0;
    } else if (a.verb == "frames") {
      wait_frames = long(number(x[0]));
    } else if (a.verb == "object-frame") {
      show_object_frame(int(number(x[0])));
      object_clock = view.object_frame;
      note(fmt::format("object frame: {}{}", view.object_frame,
                       scene.animated() ? "" : " (nothing moves in this scene)"));
    } else if (a.verb == "close") {
      glfwSetWindowShouldClose(window, GLFW_TRUE);
    } else if (a.verb == "scene") {
      set_scene(x[0], false);
    } else if (a.verb == "reload") {
      set_scene(view.scene, true);
    } else if (a.verb == "ground-truth") {
      start_truth(int(number(x[0])));
    } else if (a.verb == "wait-ground-truth") {
      if (truth.running()) {
        --script_next; // again next frame
        return;
      }
      if (!truth.error().empty()) throw ViewerError(fmt::format("{}: ground truth: {}", a.where, truth.error()));
    } else if (a.verb == "show-truth") {
      show_truth = x[0] == "on";
    } else if (a.verb == "show-map") {
      show_map = x[0] == "on";
    } else if (a.verb == "quit") {
      quit = true;
    } else if (a.verb.starts_with("light-")) {
      light_action(a);
    }
  } catch (const scene::SceneError& e) {
    throw ViewerError(fmt::format("{}: {}", a.where, e.what()));
  } catch (const ViewError& e) {
    throw ViewerError(fmt::format("{}: {}", a.where, e.what()));
  } catch (const render::RenderError& e) { throw ViewerError(fmt::format("{}: {}", a.where, e.what())); }
}

} // namespace msm::viewer
