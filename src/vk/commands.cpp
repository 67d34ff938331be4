#include "msm/vk/commands.h"

#include "msm/vk/context.h"

#include <type_traits>

namespace msm::vk {

void submit_and_wait(const Context& ctx, const std::function<void(VkCommandBuffer)>& record) {
  VkDevice device = ctx.device();
  VkCommandBufferAllocateInfo allocate_info{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                            .commandPool = ctx.command_pool(),
                                            .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                            .commandBufferCount = 1};
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkAllocateCommandBuffers(device, &allocate_info, &cmd));
  // Freed on every path: after the wait, or unsubmitted (recording) when something threw.
  struct Free {
    VkDevice device;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    ~Free() { vkFreeCommandBuffers(device, pool, 1, &cmd); }
  } free_on_exit{device, ctx.command_pool(), cmd};

  VkCommandBufferBeginInfo begin_info{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                      .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
  MSM_VK_CHECK(vkBeginCommandBuffer(cmd, &begin_info));
  record(cmd);
  pipeline_barrier(cmd, memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                       VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT));
  MSM_VK_CHECK(vkEndCommandBuffer(cmd));

  VkFenceCreateInfo fence_info{.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence raw_fence = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateFence(device, &fence_info, nullptr, &raw_fence));
  Fence fence(device, raw_fence);
  VkCommandBufferSubmitInfo cmd_info{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = cmd};
  VkSubmitInfo2 submit{
      .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .commandBufferInfoCount = 1, .pCommandBufferInfos = &cmd_info};
  MSM_VK_CHECK(vkQueueSubmit2(ctx.queue(), 1, &submit, fence));
  MSM_VK_CHECK(vkWaitForFences(device, 1, &raw_fence, VK_TRUE, UINT64_MAX));
}

namespace {

// The stages and accesses on both sides, common to the three kinds of barrier; a buffer or image
// barrier also transfers no ownership.
template <class Barrier>
Barrier barrier(VkStructureType type, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) {
  Barrier b{.sType = type};
  b.srcStageMask = src_stage;
  b.srcAccessMask = src_access;
  b.dstStageMask = dst_stage;
  b.dstAccessMask = dst_access;
  if constexpr (!std::is_same_v<Barrier, VkMemoryBarrier2>)
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  return b;
}

} // namespace

VkMemoryBarrier2 memory_barrier(VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) {
  return barrier<VkMemoryBarrier2>(VK_STRUCTURE_TYPE_MEMORY_BARRIER_2, src_stage, src_access, dst_stage, dst_access);
}

VkBufferMemoryBarrier2 buffer_barrier(VkBuffer buffer, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                      VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access, VkDeviceSize offset,
                                      VkDeviceSize size) {
  auto b = barrier<VkBufferMemoryBarrier2>(VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2, src_stage, src_access, dst_stage,
                                           dst_access);
  b.buffer = buffer;
  b.offset = offset;
  b.size = size;
  return b;
}

VkImageMemoryBarrier2 image_barrier(VkImage image, VkImageAspectFlags aspect, VkPipelineStageFlags2 src_stage,
                                    VkAccessFlags2 src_access, VkImageLayout old_layout,
                                    VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access,
                                    VkImageLayout new_layout, uint32_t base_mip, uint32_t mip_count,
                                    uint32_t base_layer, uint32_t layer_count) {
  auto b = barrier<VkImageMemoryBarrier2>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2, src_stage, src_access, dst_stage,
                                          dst_access);
  b.oldLayout = old_layout;
  b.newLayout = new_layout;
  b.image = image;
  b.subresourceRange = {aspect, base_mip, mip_count, base_layer, layer_count};
  return b;
}

void pipeline_barrier(VkCommandBuffer cmd, std::span<const VkMemoryBarrier2> memory,
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
