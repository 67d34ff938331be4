// The viewer's window, frame loop and script runner; the panel is panel.cpp.
#include "viewer_state.h"

#include "font.h"

#include "msm/image/io.h"
#include "msm/techniques.h"
#include "msm/vk/commands.h"
#include "msm/vk/context.h"
#include "msm/vk/resources.h"
#include "msm/vk/swapchain.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace msm::viewer {
namespace {

std::string glfw_error;

void on_glfw_error(int code, const char* description) { glfw_error = fmt::format("{} (GLFW {})", description, code); }

void check_imgui_vk(VkResult r) {
  if (r < 0) vk::check(r, "ImGui Vulkan backend");
}

struct Glfw {
  Glfw() {
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((!display || !*display) && (!wayland || !*wayland))
      throw ViewerError("no display: DISPLAY is not set (msm view needs a window; on a headless machine run "
                        "it under xvfb-run, or use msm render --view FILE)");
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit())
      throw ViewerError(fmt::format("cannot open the display '{}': {}", display ? display : wayland, glfw_error));
    if (!glfwVulkanSupported()) {
      glfwTerminate();
      throw ViewerError("GLFW finds no Vulkan loader with surface support: " + glfw_error);
    }
  }
  ~Glfw() { glfwTerminate(); }
  Glfw(const Glfw&) = delete;
  Glfw& operator=(const Glfw&) = delete;
};

// GLFW's callbacks reach the viewer through the window's user pointer.
void on_scroll(GLFWwindow* window, double, double dy) {
  auto* v = static_cast<Viewer*>(glfwGetWindowUserPointer(window));
  if (!ImGui::GetIO().WantCaptureMouse) v->fly_speed *= dy > 0 ? 1.25f : 0.8f;
}

} // namespace

Viewer::Viewer(const ViewerOptions& options) : view(options.view), script(options.script) {}

Viewer::~Viewer() {
  if (ctx) vkDeviceWaitIdle(ctx->device());
  if (imgui_vulkan) ImGui_ImplVulkan_Shutdown();
  if (imgui_glfw) ImGui_ImplGlfw_Shutdown();
  if (imgui_context) ImGui::DestroyContext();
  descriptor_pool.reset();
  truth_image = {};
  left.reset();
  right.reset();
  screenshot_buffer = {};
  swapchain.reset();
  command_pool.reset();
  fence.reset();
  acquired.reset();
  if (surface) vkDestroySurfaceKHR(ctx->instance(), surface, nullptr);
  ctx.reset();
  if (window) glfwDestroyWindow(window);
}

void Viewer::load() {
  View at_zero = view; // the scene as loaded: its objects move from frame 0 (show_object_frame)
  at_zero.object_frame = 0;
  scene = load_view_scene(at_zero);
  if (!view.camera) view.camera = scene.camera;
  std::error_code ec;
  if (std::filesystem::is_regular_file(view.scene, ec)) scene_time = std::filesystem::last_write_time(view.scene, ec);
  good_settings = view.settings;
}

void Viewer::open(const std::string& device) {
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window = glfwCreateWindow(view.settings.width, view.settings.height, "msm view", nullptr, nullptr);
  if (!window) throw ViewerError("cannot create the window: " + glfw_error);
  glfwSetWindowUserPointer(window, this);
  glfwSetScrollCallback(window, on_scroll);

  vk::ContextOptions options;
  options.device = device;
  options.application_name = "msm view";
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  if (!names) throw ViewerError("GLFW names no Vulkan surface extensions: " + glfw_error);
  for (uint32_t i = 0; i < count; ++i) options.instance_extensions.emplace_back(names[i]);
  options.device_extensions.emplace_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  try {
    ctx = std::make_unique<vk::Context>(options);
  } catch (const std::exception& e) { throw ViewerError(fmt::format("no usable Vulkan device: {}", e.what())); }
  if (VkResult r = glfwCreateWindowSurface(ctx->instance(), window, nullptr, &surface); r != VK_SUCCESS)
    throw ViewerError(fmt::format("cannot create a Vulkan surface for the window: {}", vk::result_name(r)));
  int w = 0, h = 0;
  glfwGetFramebufferSize(window, &w, &h);
  swapchain = std::make_unique<vk::Swapchain>(*ctx, surface, VkExtent2D{uint32_t(w), uint32_t(h)});

  VkCommandPoolCreateInfo pool{.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                               .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                               .queueFamilyIndex = ctx->queue_family()};
  VkCommandPool p = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateCommandPool(ctx->device(), &pool, nullptr, &p));
  command_pool = {ctx->device(), p};
  VkCommandBufferAllocateInfo alloc{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                    .commandPool = command_pool,
                                    .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                    .commandBufferCount = 1};
  MSM_VK_CHECK(vkAllocateCommandBuffers(ctx->device(), &alloc, &cmd));
  VkFenceCreateInfo fi{.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence f = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateFence(ctx->device(), &fi, nullptr, &f));
  fence = {ctx->device(), f};
  VkSemaphoreCreateInfo si{.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkSemaphore s = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateSemaphore(ctx->device(), &si, nullptr, &s));
  acquired = {ctx->device(), s};

  left = std::make_unique<render::Renderer>(*ctx, scene);
  show_object_frame(view.object_frame);
  init_imgui();
}

void Viewer::init_imgui() {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  imgui_context = true;
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr; // nothing written next to the user's files or under HOME
  io.LogFilename = nullptr;
  ImGui::StyleColorsDark();
  if (swapchain->srgb()) // the style's colours are sRGB values; the swapchain encodes what it gets
    for (ImVec4& c : ImGui::GetStyle().Colors)
      c = ImVec4(image::srgb_to_linear(c.x), image::srgb_to_linear(c.y), image::srgb_to_linear(c.z), c.w);
  unscaled_style = ImGui::GetStyle();
  load_font();
  ImGui_ImplGlfw_InitForVulkan(window, true);
  imgui_glfw = true;

  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 8};
  VkDescriptorPoolCreateInfo pool{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
                                  .flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT,
                                  .maxSets = 8,
                                  .poolSizeCount = 1,
                                  .pPoolSizes = &size};
  VkDescriptorPool p = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateDescriptorPool(ctx->device(), &pool, nullptr, &p));
  descriptor_pool = {ctx->device(), p};
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = ctx->instance();
  info.PhysicalDevice = ctx->physical_device();
  info.Device = ctx->device();
  info.QueueFamily = ctx->queue_family();
  info.Queue = ctx->queue();
  info.DescriptorPool = descriptor_pool;
  info.MinImageCount = swapchain->min_image_count();
  info.ImageCount = swapchain->image_count();
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  info.CheckVkResultFn = check_imgui_vk;
  if (!ImGui_ImplVulkan_Init(&info, swapchain->render_pass())) throw ViewerError("ImGui's Vulkan backend failed");
  imgui_vulkan = true;
  vk::submit_and_wait(*ctx, [](VkCommandBuffer c) { ImGui_ImplVulkan_CreateFontsTexture(c); });
  ImGui_ImplVulkan_DestroyFontUploadObjects();
}

void Viewer::load_font() {
  PanelFont font = load_panel_font(*ImGui::GetIO().Fonts, default_font_file(), kPanelFontPixels, font_ranges);
  if (font.fallback) note(font.message);
}

void Viewer::scale_panel(int width, int height) {
  PanelLayout layout = panel_layout(float(width), float(height));
  if (layout.scale == panel_scale) return;
  panel_scale = layout.scale;
  ImGui::GetStyle() = unscaled_style;
  ImGui::GetStyle().ScaleAllSizes(layout.scale);
  ImGui::GetIO().FontGlobalScale = layout.scale;
}

// A frame of one renderer; an invalid setting (the panel and the script allow combinations the
// renderer refuses) goes back to the last settings that rendered, and the message is shown and
// printed.
render::Renderer::DeviceFrame Viewer::render_side(render::Renderer& r, render::RenderSettings s, bool is_left) {
  r.set_camera(*view.camera);
  try {
    return r.render_on_device(s);
  } catch (const render::RenderError& e) {
    if (!is_left) { // settings the left technique takes but the right one refuses: no split
      report_error(fmt::format("{} (split screen off)", e.what()));
      split_technique.clear();
      return {};
    }
    report_error(fmt::format("{} (the settings that rendered kept)", e.what()));
    view.settings = good_settings;
    return r.render_on_device(view.settings);
  }
}

render::RenderSettings Viewer::split_settings() const {
  render::RenderSettings s = view.settings;
  s.technique = split_technique;
  // The right side takes front- and back-face depth where its technique does (a soft one).
  if (!msm_technique_is_soft(render::find_rendered_technique(split_technique).id)) s.front_back_depth = false;
  return s;
}

void Viewer::frame() {
  auto start = std::chrono::steady_clock::now();
  int w = 0, h = 0;
  glfwGetFramebufferSize(window, &w, &h);
  if (w <= 0 || h <= 0) { // minimized
    glfwWaitEventsTimeout(0.05);
    return;
  }
  VkExtent2D extent = swapchain->extent();
  if (recreate || extent.width != uint32_t(w) || extent.height != uint32_t(h)) {
    swapchain->recreate({uint32_t(w), uint32_t(h)});
    ImGui_ImplVulkan_SetMinImageCount(swapchain->min_image_count());
    recreate = false;
    extent = swapchain->extent();
  }
  view.settings.width = int(extent.width);
  view.settings.height = int(extent.height);

  scale_panel(w, h);
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  float dt = float(std::chrono::duration<double>(start - last_frame).count());
  last_frame = start;
  fly(std::min(dt, 0.1f));
  panel();
  ImGui::Render();

  if (std::optional<reference::Result> r = truth.take()) finish_truth(*r);
  render::Renderer::DeviceFrame a = render_side(*left, view.settings, true);
  good_settings = view.settings;
  render::Renderer::DeviceFrame b;
  if (show_truth && truth_image) {
    b.color = &truth_image;
  } else if (!split_technique.empty()) {
    if (!right) {
      right = std::make_unique<render::Renderer>(*ctx, scene);
      if (view.lights) { // drawn by the left one
        const DrawnLights drawn = drawn_lights(*view.lights);
        right->set_lights(drawn.directional, drawn.local);
      }
      if (view.object_frame > 0 && scene.animated()) right->move_objects(scene::at_frame(scene, view.object_frame));
    }
    b = render_side(*right, split_settings(), false);
  }
  push_times(a);

  std::optional<uint32_t> index = swapchain->acquire(acquired);
  if (!index) {
    recreate = true;
    return;
  }
  bool capture = !screenshot_path.empty();
  record(*index, a, b, capture);
  VkSemaphoreSubmitInfo wait{.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                             .semaphore = acquired,
                             .stageMask = VK_PIPELINE_STAGE_2_TRANSFER_BIT};
  VkSemaphoreSubmitInfo signal{.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                               .semaphore = swapchain->rendered(*index),
                               .stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT};
  VkCommandBufferSubmitInfo command{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = cmd};
  VkSubmitInfo2 submit{.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2,
                       .waitSemaphoreInfoCount = 1,
                       .pWaitSemaphoreInfos = &wait,
                       .commandBufferInfoCount = 1,
                       .pCommandBufferInfos = &command,
                       .signalSemaphoreInfoCount = 1,
                       .pSignalSemaphoreInfos = &signal};
  MSM_VK_CHECK(vkQueueSubmit2(ctx->queue(), 1, &submit, fence));
  if (!swapchain->present(*index)) recreate = true;
  // One frame in flight: the renderer's next frame overwrites the image this one blitted.
  VkFence f = fence;
  MSM_VK_CHECK(vkWaitForFences(ctx->device(), 1, &f, VK_TRUE, UINT64_MAX));
  MSM_VK_CHECK(vkResetFences(ctx->device(), 1, &f));
  if (capture) write_screenshot(extent);
  ++frames;
  if (truth.running())
    frame_ms_during_truth.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  frame_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
}

void Viewer::record(uint32_t index, const render::Renderer::DeviceFrame& a, const render::Renderer::DeviceFrame& b,
                    bool capture) {
  MSM_VK_CHECK(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo begin{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                 .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
  MSM_VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
  VkImage target = swapchain->image(index);
  VkExtent2D extent = swapchain->extent();
  // The renderer's frames were waited for; this orders the blit after their writes all the same.
  VkMemoryBarrier2 frames_done = vk::memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                                    VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  VkImageMemoryBarrier2 to_dst = vk::image_barrier(
      target, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED,
      VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  vk::pipeline_barrier(cmd, {&frames_done, 1}, {}, {&to_dst, 1});

  int32_t w = int32_t(extent.width), h = int32_t(extent.height);
  int32_t split_x = b.color ? std::clamp(int32_t(std::lround(divider * float(w))), 0, w) : w;
  auto blit = [&](const vk::Image& source, int32_t x0, int32_t x1) {
    if (x1 <= x0) return;
    int32_t sw = int32_t(source.width()), sh = int32_t(source.height());
    // Same size but for the moment between a resize and the next frame: then scaled.
    int32_t s0 = int32_t(std::lround(double(x0) * sw / w)), s1 = int32_t(std::lround(double(x1) * sw / w));
    VkImageBlit region{.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                       .srcOffsets = {{s0, 0, 0}, {s1, sh, 1}},
                       .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                       .dstOffsets = {{x0, 0, 0}, {x1, h, 1}}};
    vkCmdBlitImage(cmd, source.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region, VK_FILTER_NEAREST);
  };
  blit(*a.color, 0, split_x);
  if (b.color) blit(*b.color, split_x, w);
  if (show_map) blit_moments(a, target, extent);

  VkImageMemoryBarrier2 to_color = vk::image_barrier(
      target, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
      VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
      VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
      VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  vk::pipeline_barrier(cmd, to_color);
  swapchain->begin_overlay(cmd, index);
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd);
  vkCmdEndRenderPass(cmd);

  VkImageLayout last = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  VkPipelineStageFlags2 last_stage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
  VkAccessFlags2 last_access = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
  if (capture) {
    VkDeviceSize bytes = VkDeviceSize(w) * VkDeviceSize(h) * 4;
    if (!screenshot_buffer || screenshot_buffer.size() < bytes)
      screenshot_buffer = vk::create_buffer(*ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::Memory::host);
    vk::pipeline_barrier(cmd, vk::image_barrier(target, VK_IMAGE_ASPECT_COLOR_BIT, last_stage, last_access, last,
                                                VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                                                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL));
    VkBufferImageCopy copy{.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                           .imageExtent = {extent.width, extent.height, 1}};
    vkCmdCopyImageToBuffer(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, screenshot_buffer.handle(), 1, &copy);
    vk::pipeline_barrier(cmd, vk::buffer_barrier(screenshot_buffer.handle(), VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                                 VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                                                 VK_ACCESS_2_HOST_READ_BIT));
    last = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    last_stage = VK_PIPELINE_STAGE_2_TRANSFER_BIT;
    last_access = 0;
  }
  // Presentation is ordered by the semaphore; no access to make visible for it.
  vk::pipeline_barrier(cmd, vk::image_barrier(target, VK_IMAGE_ASPECT_COLOR_BIT, last_stage, last_access, last,
                                              VK_PIPELINE_STAGE_2_NONE, 0, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR));
  MSM_VK_CHECK(vkEndCommandBuffer(cmd));
}

// The left technique's first moment image (mip 0 of the first light), as a picture in the bottom
// right corner: transitioned for the blit and back to where the renderer left it.
void Viewer::blit_moments(const render::Renderer::DeviceFrame& a, VkImage target, VkExtent2D extent) {
  if (!a.moments) return;
  auto layout = VkImageLayout(a.moments_layout);
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(ctx->physical_device(), a.moments->format(), &props);
  if (layout == VK_IMAGE_LAYOUT_UNDEFINED || !(props.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT)) return;
  VkImage image = a.moments->handle();
  // The map's own transition, and the frame's blit before this one's writes over the same pixels.
  VkImageMemoryBarrier2 barriers[] = {
      vk::image_barrier(image, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                        VK_ACCESS_2_MEMORY_WRITE_BIT, layout, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                        VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL),
      vk::image_barrier(target, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                        VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                        VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                        VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL)};
  vk::pipeline_barrier(cmd, {}, {}, barriers);
  int32_t size = std::min<int32_t>(256, int32_t(std::min(extent.width, extent.height)) * 2 / 5);
  int32_t x0 = int32_t(extent.width) - size - 8, y0 = int32_t(extent.height) - size - 40;
  if (size > 16 && x0 >= 0 && y0 >= 0) {
    int32_t sw = int32_t(a.moments->width()), sh = int32_t(a.moments->height());
    VkImageBlit region{.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                       .srcOffsets = {{0, 0, 0}, {sw, sh, 1}},
                       .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                       .dstOffsets = {{x0, y0, 0}, {x0 + size, y0 + size, 1}}};
    vkCmdBlitImage(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                   &region, VK_FILTER_LINEAR);
  }
  vk::pipeline_barrier(cmd, vk::image_barrier(image, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0,
                                              VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                              VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, layout));
}

void Viewer::write_screenshot(VkExtent2D extent) {
  std::string path = std::exchange(screenshot_path, {});
  image::Image shot(int(extent.width), int(extent.height), 3);
  std::span<const std::uint8_t> px = screenshot_buffer.mapped<const std::uint8_t>();
  bool bgra = swapchain->format() == VK_FORMAT_B8G8R8A8_SRGB || swapchain->format() == VK_FORMAT_B8G8R8A8_UNORM;
  std::span<float> out = shot.pixels();
  for (size_t i = 0; i < shot.pixel_count(); ++i)
    for (size_t k = 0; k < 3; ++k) {
      float v = float(px[4 * i + (bgra ? 2 - k : k)]) / 255.0f;
      out[3 * i + k] = swapchain->srgb() ? image::srgb_to_linear(v) : v;
    }
  try {
    image::FileSet files;
    files.add_png(path, shot);
    files.commit();
  } catch (const image::ImageError& e) {
    error = e.what();
    if (script) throw ViewerError(fmt::format("{}: {}", script_where, e.what()));
    return;
  }
  note(fmt::format("screenshot: {} ({}x{})", path, extent.width, extent.height));
}

void Viewer::write_panel_mask(const std::string& path) {
  int w = view.settings.width, h = view.settings.height;
  image::Image mask(w, h, {"outside"}, 1.0f);
  int x0 = std::max(0, int(std::floor(panel_min.x))), y0 = std::max(0, int(std::floor(panel_min.y)));
  int x1 = std::min(w, int(std::ceil(panel_max.x))), y1 = std::min(h, int(std::ceil(panel_max.y)));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) mask.at(x, y) = 0.0f;
  try {
    image::FileSet files;
    files.add_exr(path, mask);
    files.commit();
  } catch (const image::ImageError& e) { throw ViewerError(fmt::format("{}: {}", script_where, e.what())); }
  double share = double(std::max(0, x1 - x0)) * std::max(0, y1 - y0) / (double(w) * h);
  note(fmt::format("panel-mask: {} (panel {},{} to {},{}, covering {:.0f}% of the window)", path, x0, y0, x1, y1,
                   100 * share));
}

void Viewer::start_truth(int samples) {
  if (truth.running()) return;
  scene::Scene s = scene::at_frame(scene, view.object_frame);
  s.camera = *view.camera;
  if (view.lights) apply_view_lights(*view.lights, s);
  truth_camera = *view.camera;
  size_t n = std::min<size_t>(frame_ms.size(), 10);
  frame_ms_before_truth = 0;
  for (size_t i = frame_ms.size() - n; i < frame_ms.size(); ++i) frame_ms_before_truth += frame_ms[i] / double(n);
  frame_ms_during_truth.clear();
  try {
    truth.start(std::move(s), view.settings, samples);
  } catch (const std::exception& e) {
    error = e.what();
    if (script) throw ViewerError(fmt::format("{}: {}", script_where, e.what()));
    return;
  }
  note(fmt::format("ground truth: started ({} samples per pixel, {}x{})", samples, view.settings.width,
                   view.settings.height));
}

// The technique's shadow buffer of the same view against the truth: metrics over the covered
// pixels and the false-colour error image (msm/image/metrics.h), uploaded for the right side.
void Viewer::finish_truth(const reference::Result& t) {
  render::RenderSettings s = truth.settings();
  left->set_camera(truth_camera);
  render::RenderResult r = left->render(s);
  image::Image background = t.visibility.channel("background");
  image::MetricOptions options;
  options.channel = "visibility";
  options.mask = &background;
  truth_metrics = image::compute_metrics(r.shadow, t.visibility, options);
  truth_technique = s.technique;
  image::Image error_rgb = image::error_image(r.shadow, t.visibility, 0.1, options);
  std::vector<std::uint8_t> rgb = image::to_srgb8(error_rgb);
  std::vector<std::uint8_t> rgba(error_rgb.pixel_count() * 4, 255);
  for (size_t i = 0; i < error_rgb.pixel_count(); ++i)
    for (size_t k = 0; k < 3; ++k) rgba[4 * i + k] = rgb[3 * i + k];
  truth_image = vk::create_image(*ctx, {.width = uint32_t(s.width),
                                        .height = uint32_t(s.height),
                                        .format = VK_FORMAT_R8G8B8A8_SRGB,
                                        .usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
  vk::upload_image(*ctx, truth_image, std::as_bytes(std::span(rgba)), VK_IMAGE_LAYOUT_UNDEFINED,
                   VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  show_truth = true;
  double during = 0;
  for (double ms : frame_ms_during_truth) during += ms / double(frame_ms_during_truth.size());
  note(fmt::format("ground truth: {} against {} {} samples: MAE {:.5f}, light leaking {:.5f}, over-darkening {:.5f} "
                   "({:.1f} s; frame {:.0f} ms before, {:.0f} ms while tracing, {} frames)",
                   s.technique, t.samples,
                   msm_technique_is_area_light(render::find_rendered_technique(s.technique).id) ? "soft" : "filtered",
                   truth_metrics->mae, truth_metrics->light_leaking, truth_metrics->over_darkening, truth.seconds(),
                   frame_ms_before_truth, during, frame_ms_during_truth.size()));
}

void Viewer::push_times(const render::Renderer::DeviceFrame& a) {
  passes = a.passes;
  gpu_history[history_next] = float(a.total_ms);
  history_next = (history_next + 1) % gpu_history.size();
}

void Viewer::note(const std::string& text) {
  std::fprintf(stdout, "msm view: %s\n", text.c_str());
  std::fflush(stdout);
  status = text;
}

void Viewer::run() {
  last_frame = std::chrono::steady_clock::now();
  while (!quit && !glfwWindowShouldClose(window)) {
    glfwPollEvents();
    if (script) step_script();
    if (quit) break;
    reload_if_changed();
    frame();
  }
  if (ctx) MSM_VK_CHECK(vkDeviceWaitIdle(ctx->device()));
  if (script && frames > 0) {
    double sum = 0;
    for (double ms : frame_ms) sum += ms;
    std::vector<double> sorted = frame_ms;
    std::sort(sorted.begin(), sorted.end());
    note(fmt::format("{} frames, {:.1f} ms per frame on average, median {:.1f} ms ({}x{}, {})", frames,
                     sum / double(frame_ms.size()), sorted[sorted.size() / 2], view.settings.width,
                     view.settings.height, ctx->info().name));
  }
}

int run_viewer(const ViewerOptions& options) {
  std::optional<Glfw> glfw; // outlives the viewer's window
  Viewer v(options);
  v.load(); // a bad scene is reported before the display is looked for
  glfw.emplace();
  v.open(options.device);
  v.run();
  return 0;
}

} // namespace msm::viewer
