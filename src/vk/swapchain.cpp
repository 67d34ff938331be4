#include "msm/vk/swapchain.h"

#include "msm/vk/context.h"
#include "msm/vk/resources.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace msm::vk {
namespace {

// sRGB first: the renderer's colour target is sRGB, and a blit between two sRGB formats copies the
// encoded values (decode, encode) where one into UNORM would store linear values.
VkSurfaceFormatKHR pick_format(const std::vector<VkSurfaceFormatKHR>& formats) {
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == wanted && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == wanted) return f;
  throw std::runtime_error("msm::vk: the surface offers no 8-bit RGBA/BGRA format");
}

} // namespace

Swapchain::Swapchain(const Context& ctx, VkSurfaceKHR surface, VkExtent2D wanted) : ctx_(ctx), surface_(surface) {
  VkBool32 supported = VK_FALSE;
  MSM_VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(ctx.physical_device(), ctx.queue_family(), surface, &supported));
  if (!supported)
    throw std::runtime_error(
        fmt::format("msm::vk: {} cannot present to this window from its queue family", ctx.info().name));
  uint32_t count = 0;
  MSM_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(ctx.physical_device(), surface, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  MSM_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(ctx.physical_device(), surface, &count, formats.data()));
  formats.resize(count);
  format_ = pick_format(formats);

  VkAttachmentDescription attachment{.format = format_.format,
                                     .samples = VK_SAMPLE_COUNT_1_BIT,
                                     .loadOp = VK_ATTACHMENT_LOAD_OP_LOAD,
                                     .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                                     .stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                     .stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                     .initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                     .finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference reference{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{
      .pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS, .colorAttachmentCount = 1, .pColorAttachments = &reference};
  // The caller's barriers order what comes before and after; these make the pass's own
  // attachment access wait for earlier colour/transfer writes and be visible to later commands.
  VkSubpassDependency dependencies[] = {
      {.srcSubpass = VK_SUBPASS_EXTERNAL,
       .dstSubpass = 0,
       .srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
       .dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
       .srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
       .dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT},
      {.srcSubpass = 0,
       .dstSubpass = VK_SUBPASS_EXTERNAL,
       .srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
       .dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
       .srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
       .dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT}};
  VkRenderPassCreateInfo info{.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO,
                              .attachmentCount = 1,
                              .pAttachments = &attachment,
                              .subpassCount = 1,
                              .pSubpasses = &subpass,
                              .dependencyCount = 2,
                              .pDependencies = dependencies};
  VkRenderPass pass = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateRenderPass(ctx.device(), &info, nullptr, &pass));
  render_pass_ = {ctx.device(), pass};
  try {
    create(wanted);
  } catch (...) {
    destroy_images();
    throw;
  }
}

Swapchain::~Swapchain() {
  vkDeviceWaitIdle(ctx_.device());
  destroy_images();
}

bool Swapchain::srgb() const noexcept {
  return format_.format == VK_FORMAT_B8G8R8A8_SRGB || format_.format == VK_FORMAT_R8G8B8A8_SRGB;
}

void Swapchain::destroy_images() noexcept {
  framebuffers_.clear();
  views_.clear();
  rendered_.clear();
  images_.clear();
  if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
}

void Swapchain::recreate(VkExtent2D wanted) {
  MSM_VK_CHECK(vkDeviceWaitIdle(ctx_.device()));
  framebuffers_.clear();
  views_.clear();
  rendered_.clear();
  create(wanted); // hands the old swapchain over as oldSwapchain, then destroys it
}

void Swapchain::create(VkExtent2D wanted) {
  VkSurfaceCapabilitiesKHR caps{};
  MSM_VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physical_device(), surface_, &caps));
  VkImageUsageFlags usage =
      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if ((caps.supportedUsageFlags & usage) != usage)
    throw std::runtime_error("msm::vk: the surface's images cannot be transfer sources and destinations");
  // currentExtent is the window's size where the surface knows it (X11), else ours within the limits.
  extent_ = caps.currentExtent.width != UINT32_MAX
                ? caps.currentExtent
                : VkExtent2D{std::clamp(wanted.width, caps.minImageExtent.width, caps.maxImageExtent.width),
                             std::clamp(wanted.height, caps.minImageExtent.height, caps.maxImageExtent.height)};
  extent_.width = std::max(extent_.width, 1u);
  extent_.height = std::max(extent_.height, 1u);
  min_image_count_ = std::max(caps.minImageCount + 1, 2u);
  if (caps.maxImageCount > 0) min_image_count_ = std::min(min_image_count_, caps.maxImageCount);
  VkSwapchainKHR old = swapchain_;
  VkSwapchainCreateInfoKHR info{.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR,
                                .surface = surface_,
                                .minImageCount = min_image_count_,
                                .imageFormat = format_.format,
                                .imageColorSpace = format_.colorSpace,
                                .imageExtent = extent_,
                                .imageArrayLayers = 1,
                                .imageUsage = usage,
                                .imageSharingMode = VK_SHARING_MODE_EXCLUSIVE,
                                .preTransform = caps.currentTransform,
                                .compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR,
                                .presentMode = VK_PRESENT_MODE_FIFO_KHR, // the one every device has
                                .clipped = VK_TRUE,
                                .oldSwapchain = old};
  if (!(caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR))
    info.compositeAlpha = VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR;
  VkResult result = vkCreateSwapchainKHR(ctx_.device(), &info, nullptr, &swapchain_);
  if (old) vkDestroySwapchainKHR(ctx_.device(), old, nullptr);
  if (result != VK_SUCCESS) {
    swapchain_ = VK_NULL_HANDLE;
    MSM_VK_CHECK(result);
  }
  ++generation_;

  uint32_t count = 0;
  MSM_VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &count, nullptr));
  images_.resize(count);
  MSM_VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &count, images_.data()));
  for (uint32_t i = 0; i < count; ++i) {
    views_.push_back(
        create_image_view(ctx_, images_[i], format_.format, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D, 0, 1));
    VkImageView view = views_.back();
    VkFramebufferCreateInfo fb{.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO,
                               .renderPass = render_pass_,
                               .attachmentCount = 1,
                               .pAttachments = &view,
                               .width = extent_.width,
                               .height = extent_.height,
                               .layers = 1};
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateFramebuffer(ctx_.device(), &fb, nullptr, &framebuffer));
    framebuffers_.emplace_back(ctx_.device(), framebuffer);
    VkSemaphoreCreateInfo si{.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore semaphore = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateSemaphore(ctx_.device(), &si, nullptr, &semaphore));
    rendered_.emplace_back(ctx_.device(), semaphore);
  }
}

std::optional<uint32_t> Swapchain::acquire(VkSemaphore acquired) {
  uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_, UINT64_MAX, acquired, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) return std::nullopt;
  if (r != VK_SUBOPTIMAL_KHR) MSM_VK_CHECK(r);
  return index; // suboptimal: still presentable, present() reports it
}

bool Swapchain::present(uint32_t index) {
  VkSemaphore wait = rendered(index);
  VkPresentInfoKHR info{.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR,
                        .waitSemaphoreCount = 1,
                        .pWaitSemaphores = &wait,
                        .swapchainCount = 1,
                        .pSwapchains = &swapchain_,
                        .pImageIndices = &index};
  VkResult r = vkQueuePresentKHR(ctx_.queue(), &info);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return false;
  MSM_VK_CHECK(r);
  return true;
}

void Swapchain::begin_overlay(VkCommandBuffer cmd, uint32_t index) const {
  VkRenderPassBeginInfo info{.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
                             .renderPass = render_pass_,
                             .framebuffer = framebuffers_.at(index),
                             .renderArea = {{0, 0}, extent_}};
  vkCmdBeginRenderPass(cmd, &info, VK_SUBPASS_CONTENTS_INLINE);
}

} // namespace msm::vk
