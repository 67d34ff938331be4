// Command recording helpers: one-shot submission and synchronization2 barriers.
#pragma once

#include "msm/vk/common.h"

#include <functional>
#include <span>

namespace msm::vk {

class Context;

// Allocates a primary command buffer from ctx.commandPool(), lets `record` fill it, submits it
// (vkQueueSubmit2) and waits on a fence. A final barrier (all writes -> host reads) makes what the
// commands wrote visible to the host, so a Host buffer can be read right after the return. If
// `record` throws, nothing is submitted and the exception propagates. For tests, uploads and
// readbacks, not for per-frame work (it stalls).
void submitAndWait(const Context& ctx, const std::function<void(VkCommandBuffer)>& record);

// Barrier structs for vkCmdPipelineBarrier2; queue family ownership is never transferred.
VkMemoryBarrier2 memoryBarrier(VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                               VkAccessFlags2 dstAccess);

VkBufferMemoryBarrier2 bufferBarrier(VkBuffer buffer, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                                     VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess, VkDeviceSize offset = 0,
                                     VkDeviceSize size = VK_WHOLE_SIZE);

// Covers mips [baseMip, baseMip + mipCount) of all layers.
VkImageMemoryBarrier2 imageBarrier(VkImage image, VkImageAspectFlags aspect, VkPipelineStageFlags2 srcStage,
                                   VkAccessFlags2 srcAccess, VkImageLayout oldLayout, VkPipelineStageFlags2 dstStage,
                                   VkAccessFlags2 dstAccess, VkImageLayout newLayout, uint32_t baseMip = 0,
                                   uint32_t mipCount = VK_REMAINING_MIP_LEVELS);

// vkCmdPipelineBarrier2 with any mix of barriers.
void pipelineBarrier(VkCommandBuffer cmd, std::span<const VkMemoryBarrier2> memory,
                     std::span<const VkBufferMemoryBarrier2> buffers, std::span<const VkImageMemoryBarrier2> images,
                     VkDependencyFlags flags = 0);
inline void pipelineBarrier(VkCommandBuffer cmd, const VkMemoryBarrier2& barrier) {
  pipelineBarrier(cmd, {&barrier, 1}, {}, {});
}
inline void pipelineBarrier(VkCommandBuffer cmd, const VkBufferMemoryBarrier2& barrier) {
  pipelineBarrier(cmd, {}, {&barrier, 1}, {});
}
inline void pipelineBarrier(VkCommandBuffer cmd, const VkImageMemoryBarrier2& barrier) {
  pipelineBarrier(cmd, {}, {}, {&barrier, 1});
}

} // namespace msm::vk
