// A window's swapchain and the one render pass a viewer needs on it: an overlay pass that draws
// over what is already in the image (Dear ImGui's Vulkan backend wants a VkRenderPass; the rest of
// msm renders with dynamic rendering). The window system is not known here: the caller creates the
// surface (GLFW: glfwCreateWindowSurface) on ctx.instance(), with the instance extensions it needs
// and VK_KHR_swapchain on the device (ContextOptions::instance_extensions, device_extensions).
//
//   Swapchain sc(ctx, surface, {width, height});
//   auto index = sc.acquire(acquired);           // nullopt: out of date, recreate(new size) and retry
//   ... transfer into sc.image(*index) (TRANSFER_DST), then
//   sc.begin_overlay(cmd, *index); draw; vkCmdEndRenderPass(cmd);   // COLOR_ATTACHMENT_OPTIMAL in and out
//   ... barrier to PRESENT_SRC_KHR, submit signalling sc.rendered(*index), then sc.present(*index)
#pragma once

#include "msm/vk/common.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace msm::vk {

class Context;

class Swapchain {
 public:
  // Throws Error / std::runtime_error when the device's queue cannot present to the surface or the
  // surface offers no usable format. The surface must outlive the Swapchain.
  Swapchain(const Context& ctx, VkSurfaceKHR surface, VkExtent2D wanted);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // A new swapchain of (about) this size, e.g. after the window was resized; waits for the device
  // to be idle first. The render pass stays (same format); framebuffers and semaphores are new.
  void recreate(VkExtent2D wanted);
  // How many times the swapchain was (re)created: 1 after construction.
  int generation() const noexcept { return generation_; }

  // The next image, signalling `acquired`; nullopt when the swapchain is out of date (recreate).
  std::optional<uint32_t> acquire(VkSemaphore acquired);
  // Presents after `rendered(index)` is signalled; false when out of date or suboptimal (recreate).
  bool present(uint32_t index);

  VkFormat format() const noexcept { return format_.format; }
  // Whether the images encode to sRGB on write (an _SRGB format): blits from sRGB images then copy
  // the encoded values, and overlay colours given in sRGB must be linearized first.
  bool srgb() const noexcept;
  VkExtent2D extent() const noexcept { return extent_; }
  uint32_t image_count() const noexcept { return uint32_t(images_.size()); }
  uint32_t min_image_count() const noexcept { return min_image_count_; }
  VkImage image(uint32_t index) const { return images_.at(index); }
  // Signalled by the submission that finishes image `index`, waited for by present(index).
  VkSemaphore rendered(uint32_t index) const { return rendered_.at(index).get(); }
  VkRenderPass render_pass() const noexcept { return render_pass_.get(); }

  // The overlay pass over image `index` (LOAD, STORE; COLOR_ATTACHMENT_OPTIMAL before and after).
  void begin_overlay(VkCommandBuffer cmd, uint32_t index) const;

 private:
  void create(VkExtent2D wanted);
  void destroy_images() noexcept;

  const Context& ctx_;
  VkSurfaceKHR surface_;
  VkSurfaceFormatKHR format_{};
  Unique<VkRenderPass, vkDestroyRenderPass> render_pass_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  std::vector<VkImage> images_;
  std::vector<ImageView> views_;
  std::vector<Unique<VkFramebuffer, vkDestroyFramebuffer>> framebuffers_;
  std::vector<Semaphore> rendered_;
  VkExtent2D extent_{};
  uint32_t min_image_count_ = 2;
  int generation_ = 0;
};

} // namespace msm::vk
