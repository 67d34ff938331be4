#include "pass.h"

#include <algorithm>

namespace msm::render {

void MipmapPass::reflect(PassBuilder& b) const {
  for (int i = 0; i < config_.moment_images(); ++i) {
    b.modify(moment_image(channel_, i), use::transfer_source());
    b.internally(moment_image(channel_, i), use::transfer_destination()); // each mip while it is blitted
  }
}

// Each mip is the 2x2 box average of the previous one (a linear blit): averages of moments are
// moments, so every mip is a valid, more strongly filtered moment map. The graph hands over every
// mip in TRANSFER_SRC; each is rewritten from the previous one and left there again.
void MipmapPass::execute(const PassContext& c) const {
  for (int i = 0; i < config_.moment_images(); ++i)
    record_mip_chain(c.cmd, c.image(moment_image(channel_, i)).image.handle(), config_.shadow_size,
                     config_.blur_writes_mip1() ? 2 : 1, config_.mip_levels, uint32_t(config_.lights));
}

void record_mip_chain(VkCommandBuffer cmd, VkImage image, int32_t size, uint32_t first_mip, uint32_t mips,
                      uint32_t layers) {
  constexpr VkImageAspectFlags color = VK_IMAGE_ASPECT_COLOR_BIT;
  constexpr VkPipelineStageFlags2 transfer = VK_PIPELINE_STAGE_2_TRANSFER_BIT;
  for (uint32_t mip = first_mip; mip < mips; ++mip) {
    vk::pipeline_barrier(cmd, vk::image_barrier(image, color, transfer, VK_ACCESS_2_TRANSFER_READ_BIT,
                                                VK_IMAGE_LAYOUT_UNDEFINED, transfer, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, mip, 1));
    int32_t src = std::max(size >> (mip - 1), 1), dst = std::max(size >> mip, 1);
    VkImageBlit2 region{.sType = VK_STRUCTURE_TYPE_IMAGE_BLIT_2,
                        .srcSubresource = {color, mip - 1, 0, layers},
                        .srcOffsets = {{0, 0, 0}, {src, src, 1}},
                        .dstSubresource = {color, mip, 0, layers},
                        .dstOffsets = {{0, 0, 0}, {dst, dst, 1}}};
    VkBlitImageInfo2 blit{.sType = VK_STRUCTURE_TYPE_BLIT_IMAGE_INFO_2,
                          .srcImage = image,
                          .srcImageLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                          .dstImage = image,
                          .dstImageLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          .regionCount = 1,
                          .pRegions = &region,
                          .filter = VK_FILTER_LINEAR};
    vkCmdBlitImage2(cmd, &blit);
    vk::pipeline_barrier(cmd, vk::image_barrier(image, color, transfer, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, transfer,
                                                VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                                mip, 1));
  }
}

} // namespace msm::render
