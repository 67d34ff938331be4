// The viewer's state, shared by its frame loop (viewer.cpp) and its panel, camera and script
// (panel.cpp). Every change the panel makes goes through the same members a script action sets.
#pragma once

#include "ground_truth.h"
#include "panel_layout.h"
#include "setting_controls.h"

#include "msm/image/metrics.h"
#include "msm/render/renderer.h"
#include "msm/viewer/viewer.h"
#include "msm/vk/common.h"
#include "msm/vk/resources.h"

#include <imgui.h>

#include <array>
#include <chrono>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct GLFWwindow;

namespace msm::vk {
class Context;
class Swapchain;
} // namespace msm::vk

namespace msm::viewer {

struct Viewer {
  explicit Viewer(const ViewerOptions& options);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  void load(); // the scene
  void open(const std::string& device);
  void run();

  // viewer.cpp
  void init_imgui();
  void load_font();
  // The panel's scale for the window's size (panel_layout.h), before the frame's ImGui::NewFrame.
  void scale_panel(int width, int height);
  void frame();
  void record(uint32_t index, const render::Renderer::DeviceFrame& a, const render::Renderer::DeviceFrame& b,
              bool capture);
  render::Renderer::DeviceFrame render_side(render::Renderer& r, render::RenderSettings s, bool is_left);
  render::RenderSettings split_settings() const;
  void blit_moments(const render::Renderer::DeviceFrame& a, VkImage target, VkExtent2D extent);
  void write_screenshot(VkExtent2D extent);
  void write_panel_mask(const std::string& path);
  void push_times(const render::Renderer::DeviceFrame& a);
  void note(const std::string& text); // stdout and the panel's status line
  void start_truth(int samples);
  void finish_truth(const reference::Result& truth);

  // panel.cpp
  void panel();
  // The panel's parts, each drawn by panel() under its header.
  void choices_section();
  void technique_settings_section();
  void light_shape_controls(render::RenderSettings& settings, const SettingControl& control);
  void light_and_camera_section();
  void gpu_time_section();
  void ground_truth_section();
  void files_section();
  void lights_section();
  void fly(float dt);
  void move_selected_light(float dt); // the arrow keys, PgUp and PgDn
  void step_script();
  void light_action(const Action& a); // the script's light-* actions
  // The actions of the panel and the script.
  void set_technique(const std::string& name);
  void set_split(const std::string& name); // empty: off
  void set_light_direction(glm::vec3 towards);
  // The animated objects at this frame (scene::at_frame) in both renderers; view.object_frame.
  void show_object_frame(int frame);
  void save_view_file(const std::string& path);
  // Another scene (its camera and lights), or the same file again (the view kept, the scene's
  // lights taken again); SceneError leaves everything as it was, and so does a scene or view that
  // the renderer refuses (reported; false then).
  bool set_scene(const std::string& name, bool keep_view);
  void reload_if_changed(); // a scene file whose modification time changed
  void copy_command();
  glm::vec3 light_direction() const; // of the first directional light (straight up where none)
  // The view's lights (View::lights), or the scene's as the renderer draws them.
  std::vector<ViewLight> light_list() const;
  // Draws `next` from the next frame on. False where the renderer refuses them (a kind it does not
  // draw, settings it does not take with them): the message shown and printed, the lights kept.
  bool set_lights(std::vector<ViewLight> next);
  // The scene's own lights again, the view's dropped.
  void reset_lights();
  // A refusal that leaves the viewer as it was: in the panel and printed (script: with its line).
  void report_error(const std::string& message);

  View view;
  render::RenderSettings good_settings; // the last settings that rendered
  scene::Scene scene;
  std::optional<std::filesystem::file_time_type> scene_time; // of a scene file
  std::chrono::steady_clock::time_point scene_checked;
  std::string split_technique; // empty: no split screen
  float divider = 0.5f;
  bool dragging_divider = false;

  GLFWwindow* window = nullptr;
  std::unique_ptr<vk::Context> ctx;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  std::unique_ptr<vk::Swapchain> swapchain;
  vk::Unique<VkCommandPool, vkDestroyCommandPool> command_pool;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  vk::Fence fence;
  vk::Semaphore acquired;
  vk::Unique<VkDescriptorPool, vkDestroyDescriptorPool> descriptor_pool;
  vk::Buffer screenshot_buffer;
  std::unique_ptr<render::Renderer> left, right;
  bool imgui_context = false, imgui_glfw = false, imgui_vulkan = false;
  bool recreate = false;
  bool quit = false;

  // Times: GPU per pass of the left frame, a history of its total, wall time per frame.
  std::vector<render::PassTime> passes;
  std::array<float, 120> gpu_history{};
  size_t history_next = 0;
  std::vector<double> frame_ms;
  long frames = 0;
  std::chrono::steady_clock::time_point last_frame;

  // Camera fly and light animation.
  float fly_speed = 2.0f;  // scene units per second; also the selected light's (arrow keys)
  int selected_light = -1; // in light_list(), -1: none
  bool animate_light = false;
  float light_speed_deg = 20.0f;
  // Object animation: the scene's "motion" frames advance at object_rate per second.
  bool animate_objects = false;
  float object_rate = 10.0f;
  double object_clock = 0.0;

  ImVec2 panel_min{0, 0}, panel_max{0, 0};
  ImVector<ImWchar> font_ranges;      // read by the font atlas when it is built
  ImGuiStyle unscaled_style;          // ImGuiStyle::ScaleAllSizes compounds: always from this one
  float panel_scale = 0.0f;           // 0: not yet scaled
  std::optional<bool> small_window;   // the panel_layout's collapsed default last applied
  std::optional<bool> collapse_panel; // the script's `panel open|collapsed`, for the next frame
  std::string status, error;
  std::string view_path = "msm-view.json";
  std::string screenshot_path; // non-empty: captured this frame
  int screenshot_count = 0;

  // The ray-traced ground truth of the view (on demand, in the background) and the technique's
  // false-colour error against it, shown right of the divider.
  GroundTruth truth;
  int truth_samples = 16;
  scene::Camera truth_camera;
  bool show_truth = false;
  bool show_map = false; // the left technique's moment image in a corner
  vk::Image truth_image;
  std::optional<image::Metrics> truth_metrics;
  std::string truth_technique;
  std::vector<double> frame_ms_during_truth;
  double frame_ms_before_truth = 0;
  bool wait_truth = false;

  std::optional<std::vector<Action>> script;
  size_t script_next = 0;
  long wait_frames = 0;
  std::optional<std::pair<int, int>> pending_resize;
  int resize_tries = 0;
  std::string script_where;
};

} // namespace msm::viewer
