// msm::viewer: `msm view`, a GLFW window with a Vulkan swapchain on the same msm::vk context and
// msm::render::Renderer as `msm render`, and a Dear ImGui panel. Each frame the renderer draws the
// view offscreen (Renderer::render_on_device), the frame is blitted into the swapchain image (the
// right part from a second renderer in split screen) and the panel is drawn over it in the vk
// layer's overlay pass (vk::Swapchain). Built with MSM_BUILD_VIEWER (GLFW and imgui found).
#pragma once

#include "msm/viewer/script.h"
#include "msm/viewer/view_file.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace msm::viewer {

// No display, no Vulkan surface support, a failed script action: the message says which.
class ViewerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ViewerOptions {
  View view;
  std::optional<std::vector<Action>> script; // run one action per frame; the window stays open after
  std::string device;                        // vk::ContextOptions::device
};

// Runs until the window is closed or a script says quit; returns the exit status (0). Throws
// ViewerError (and SceneError / RenderError for bad input).
int run_viewer(const ViewerOptions& options);

} // namespace msm::viewer
