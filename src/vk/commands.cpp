#include "msm/vk/commands.h"

#include "msm/vk/context.h"

namespace msm::vk {

void submitAndWait(const Context& ctx, const std::function<void(VkCommandBuffer)>& record) {
  VkDevice device = ctx.device();
  VkCommandBufferAllocateInfo allocateInfo{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                           .commandPool = ctx.commandPool(),
                                           .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                           .commandBufferCount = 1};
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkAllocateCommandBuffers(device, &allocateInfo, &cmd));
  // Freed on every path: after the wait, or unsubmitted (recording) when something threw.
  struct Free {
    VkDevice device;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    ~Free() { vkFreeCommandBuffers(device, pool, 1, &cmd); }
  } freeOnExit{device, ctx.commandPool(), cmd};

  VkCommandBufferBeginInfo beginInfo{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                     .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
  MSM_VK_CHECK(vkBeginCommandBuffer(cmd, &beginInfo));
  record(cmd);
  pipelineBarrier(cmd, memoryBarrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                     VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT));
  MSM_VK_CHECK(vkEndCommandBuffer(cmd));

  VkFenceCreateInfo fenceInfo{.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence rawFence = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateFence(device, &fenceInfo, nullptr, &rawFence));
  Fence fence(device, rawFence);
  VkCommandBufferSubmitInfo cmdInfo{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = cmd};
  VkSubmitInfo2 submit{.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .commandBufferInfoCount = 1, .pCommandBufferInfos = &cmdInfo};
  MSM_VK_CHECK(vkQueueSubmit2(ctx.queue(), 1, &submit, fence));
  MSM_VK_CHECK(vkWaitForFences(device, 1, &rawFence, VK_TRUE, UINT64_MAX));
}

VkMemoryBarrier2 memoryBarrier(VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                               VkAccessFlags2 dstAccess) {
  return {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
          .srcStageMask = srcStage,
          .srcAccessMask = srcAccess,
          .dstStageMask = dstStage,
          .dstAccessMask = dstAccess};
}

VkBufferMemoryBarrier2 bufferBarrier(VkBuffer buffer, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                                     VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess, VkDeviceSize offset,
                                     VkDeviceSize size) {
  return {.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2,
          .srcStageMask = srcStage,
          .srcAccessMask = srcAccess,
          .dstStageMask = dstStage,
          .dstAccessMask = dstAccess,
          .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
          .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
          .buffer = buffer,
          .offset = offset,
          .size = size};
}

VkImageMemoryBarrier2 imageBarrier(VkImage image, VkImageAspectFlags aspect, VkPipelineStageFlags2 srcStage,
                                   VkAccessFlags2 srcAccess, VkImageLayout oldLayout, VkPipelineStageFlags2 dstStage,
                                   VkAccessFlags2 dstAccess, VkImageLayout newLayout, uint32_t baseMip,
                                   uint32_t mipCount) {
  return {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
          .srcStageMask = srcStage,
          .srcAccessMask = srcAccess,
          .dstStageMask = dstStage,
          .dstAccessMask = dstAccess,
          .oldLayout = oldLayout,
          .newLayout = newLayout,
          .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
          .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
          .image = image,
          .subresourceRange = {aspect, baseMip, mipCount, 0, VK_REMAINING_ARRAY_LAYERS}};
}

void pipelineBarrier(VkCommandBuffer cmd, std::span<const VkMemoryBarrier2> memory,
                     std::span<const VkBufferMemoryBarrier2> buffers, std::span<const VkImageMemoryBarrier2> images,
                     VkDependencyFlags flags) {
  VkDependencyInfo info{.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                        .dependencyFlags = flags,
                        .memoryBarrierCount = uint32_t(memory.size()),
                        .pMemoryBarriers = memory.data(),
                        .bufferMemoryBarrierCount = uint32_t(buffers.size()),
                        .pBufferMemoryBarriers = buffers.data(),
                        .imageMemoryBarrierCount = uint32_t(images.size()),
                        .pImageMemoryBarriers = images.data()};
  vkCmdPipelineBarrier2(cmd, &info);
}

} // namespace msm::vk
