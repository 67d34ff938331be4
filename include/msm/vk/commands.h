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
void submit_and_wait(const Context& ctx, const std::function<void(VkCommandBuffer)>& record);

// Barrier structs for vkCmdPipelineBarrier2; queue family ownership is never transferred.
VkMemoryBarrier2 memory_barrier(VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access);

VkBufferMemoryBarrier2 buffer_barrier(VkBuffer buffer, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                      VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access,
                                      VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE);

// Covers mips [base_mip, base_mip + mip_count) of layers [base_layer, base_layer + layer_count).
VkImageMemoryBarrier2 image_barrier(VkImage image, VkImageAspectFlags aspect, VkPipelineStageFlags2 src_stage,
                                    VkAccessFlags2 src_access, VkImageLayout old_layout,
                                    VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access,
                                    VkImageLayout new_layout, uint32_t base_mip = 0,
                                    uint32_t mip_count = VK_REMAINING_MIP_LEVELS, uint32_t base_layer = 0,
                                    uint32_t layer_count = VK_REMAINING_ARRAY_LAYERS);

// vkCmdPipelineBarrier2 with any mix of barriers.
void pipeline_barrier(VkCommandBuffer cmd, std::span<const VkMemoryBarrier2> memory,
                      std::span<const VkBufferMemoryBarrier2> buffers, std::span<const VkImageMemoryBarrier2> images,
                      VkDependencyFlags flags = 0);
inline void pipeline_barrier(VkCommandBuffer cmd, const VkMemoryBarrier2& barrier) {
  pipeline_barrier(cmd, {&barrier, 1}, {}, {});
}
inline void pipeline_barrier(VkCommandBuffer cmd, const VkBufferMemoryBarrier2& barrier) {
  pipeline_barrier(cmd, {}, {&barrier, 1}, {});
}
inline void pipeline_barrier(VkCommandBuffer cmd, const VkImageMemoryBarrier2& barrier) {
  pipeline_barrier(cmd, {}, {}, {&barrier, 1});
}

} // namespace msm::vk
