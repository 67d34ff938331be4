#include "pass.h"

#include <vector>

namespace msm::render {

const PassDecl& MomentResolvePass::decl() {
  static const PassDecl d{"moment_resolve", {"shadow_depth", "frame.technique_params"}, {"moments"}};
  return d;
}

MomentResolvePass::MomentResolvePass(const vk::Context& ctx, const Technique& technique, int msaa, bool split_rg)
    : program_(vk::create_program(ctx, msaa == 1 ? "moment_resolve_1x.comp" : "moment_resolve.comp",
                                  {vk::Binding::uniform_buffer, vk::Binding::sampled_image, vk::Binding::storage_image,
                                   vk::Binding::storage_image},
                                  sizeof(ImagePassPush), {{0, uint32_t(technique.id)}, {3, split_rg ? 1u : 0u}})) {}

void MomentResolvePass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  int images = t.config.moment_images();
  for (int i = 0; i < images; ++i)
    vk::pipeline_barrier(f.cmd, vk::image_barrier(t.moment_image(f.channel, i).handle(), VK_IMAGE_ASPECT_COLOR_BIT,
                                                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED,
                                                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL, 0, 1));
  // The shader writes image 1 only for 6MSM; the others get image 0 twice (a valid descriptor).
  VkImageView first = t.moment_mip0(f.channel, 0), second = images > 1 ? t.moment_mip0(f.channel, 1) : first;
  ImagePassPush push{glm::ivec4(t.config.shadow_size, t.config.shadow_size, 0, 0)};
  uint32_t groups = vk::group_count(uint32_t(t.config.shadow_size), 8);
  vk::dispatch(f.cmd, program_, groups, groups, 1,
               {vk::Descriptor(f.uniforms),
                vk::Descriptor(t.shadow_depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler),
                vk::Descriptor(first, VK_IMAGE_LAYOUT_GENERAL), vk::Descriptor(second, VK_IMAGE_LAYOUT_GENERAL)},
               push);
  vk::pipeline_barrier(
      f.cmd, vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                    VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT |
                                    VK_ACCESS_2_TRANSFER_WRITE_BIT));
  // Coloured translucency: the other channels start from the same opaque moments (transfer
  // layouts for the copy; everything back in GENERAL, as the resolve leaves channel 0).
  if (t.config.channels() == 1) return;
  constexpr VkImageAspectFlags color = VK_IMAGE_ASPECT_COLOR_BIT;
  constexpr VkPipelineStageFlags2 transfer = VK_PIPELINE_STAGE_2_TRANSFER_BIT;
  std::vector<VkImageMemoryBarrier2> to_transfer, to_general;
  for (int i = 0; i < images; ++i) {
    VkImage src = t.moment_image(0, i).handle();
    to_transfer.push_back(vk::image_barrier(src, color, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL, transfer,
                                            VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, 0, 1));
    to_general.push_back(vk::image_barrier(src, color, transfer, VK_ACCESS_2_TRANSFER_READ_BIT,
                                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                           VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                                           VK_IMAGE_LAYOUT_GENERAL, 0, 1));
    for (int c = 1; c < t.config.channels(); ++c) {
      VkImage dst = t.moment_image(c, i).handle();
      to_transfer.push_back(vk::image_barrier(dst, color, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0,
                                              VK_IMAGE_LAYOUT_UNDEFINED, transfer, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                              VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, 1));
      to_general.push_back(vk::image_barrier(dst, color, transfer, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                             VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                                             VK_IMAGE_LAYOUT_GENERAL, 0, 1));
    }
  }
  vk::pipeline_barrier(f.cmd, {}, {}, to_transfer);
  for (int i = 0; i < images; ++i)
    for (int c = 1; c < t.config.channels(); ++c) {
      VkImageCopy2 region{.sType = VK_STRUCTURE_TYPE_IMAGE_COPY_2,
                          .srcSubresource = {color, 0, 0, 1},
                          .dstSubresource = {color, 0, 0, 1},
                          .extent = {uint32_t(t.config.shadow_size), uint32_t(t.config.shadow_size), 1}};
      VkCopyImageInfo2 copy{.sType = VK_STRUCTURE_TYPE_COPY_IMAGE_INFO_2,
                            .srcImage = t.moment_image(0, i).handle(),
                            .srcImageLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            .dstImage = t.moment_image(c, i).handle(),
                            .dstImageLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                            .regionCount = 1,
                            .pRegions = &region};
      vkCmdCopyImage2(f.cmd, &copy);
    }
  vk::pipeline_barrier(f.cmd, {}, {}, to_general);
}

} // namespace msm::render
