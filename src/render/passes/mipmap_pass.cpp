#include "pass.h"

#include <algorithm>

namespace msm::render {

const PassDecl& MipmapPass::decl() {
  static const PassDecl d{"mipmaps", {"moments"}, {"moments"}};
  return d;
}

// Each mip is the 2x2 box average of the previous one (a linear blit): averages of moments are
// moments, so every mip is a valid, more strongly filtered moment map. Without mips (one level)
// this only hands mip 0 over to the shading.
void MipmapPass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  constexpr VkImageAspectFlags color = VK_IMAGE_ASPECT_COLOR_BIT;
  constexpr VkPipelineStageFlags2 transfer = VK_PIPELINE_STAGE_2_TRANSFER_BIT;
  constexpr VkPipelineStageFlags2 compute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  for (int i = 0; i < t.config.moment_images(); ++i) {
    VkImage image = t.moment_image(f.channel, i).handle();
    int32_t size = t.config.shadow_size;
    uint32_t levels = t.mip_levels;
    if (levels == 1) {
      vk::pipeline_barrier(f.cmd, vk::image_barrier(image, color, compute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                                    VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                                    VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                                                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, 1));
      continue;
    }
    VkImageMemoryBarrier2 start[2] = {
        vk::image_barrier(image, color, compute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL,
                          transfer, VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, 0, 1),
        vk::image_barrier(image, color, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED, transfer,
                          VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, levels - 1)};
    vk::pipeline_barrier(f.cmd, {}, {}, start);
    for (uint32_t mip = 1; mip < levels; ++mip) {
      int32_t src = std::max(size >> (mip - 1), 1), dst = std::max(size >> mip, 1);
      VkImageBlit2 region{.sType = VK_STRUCTURE_TYPE_IMAGE_BLIT_2,
                          .srcSubresource = {color, mip - 1, 0, 1},
                          .srcOffsets = {{0, 0, 0}, {src, src, 1}},
                          .dstSubresource = {color, mip, 0, 1},
                          .dstOffsets = {{0, 0, 0}, {dst, dst, 1}}};
      VkBlitImageInfo2 blit{.sType = VK_STRUCTURE_TYPE_BLIT_IMAGE_INFO_2,
                            .srcImage = image,
                            .srcImageLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            .dstImage = image,
                            .dstImageLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                            .regionCount = 1,
                            .pRegions = &region,
                            .filter = VK_FILTER_LINEAR};
      vkCmdBlitImage2(f.cmd, &blit);
      vk::pipeline_barrier(f.cmd, vk::image_barrier(image, color, transfer, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, transfer,
                                                    VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                                    mip, 1));
    }
    vk::pipeline_barrier(
        f.cmd,
        vk::image_barrier(image, color, transfer, VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_TRANSFER_READ_BIT,
                          VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, levels));
  }
}

} // namespace msm::render
