#include "pass.h"

namespace msm::render {

const PassDecl& MomentResolvePass::decl() {
  static const PassDecl d{"moment_resolve", {"shadow_depth", "frame.technique_params"}, {"moments"}};
  return d;
}

MomentResolvePass::MomentResolvePass(const vk::Context& ctx, const Technique& technique, int msaa, bool split_rg)
    : program_(vk::createProgram(ctx, msaa == 1 ? "moment_resolve_1x.comp" : "moment_resolve.comp",
                                 {vk::Binding::UniformBuffer, vk::Binding::SampledImage, vk::Binding::StorageImage,
                                  vk::Binding::StorageImage},
                                 sizeof(ImagePassPush), {{0, uint32_t(technique.id)}, {3, split_rg ? 1u : 0u}})) {}

void MomentResolvePass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  int images = t.config.moment_images();
  for (int i = 0; i < images; ++i)
    vk::pipelineBarrier(f.cmd, vk::imageBarrier(t.moment_image(f.channel, i).handle(), VK_IMAGE_ASPECT_COLOR_BIT,
                                                VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED,
                                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL, 0, 1));
  // The shader writes image 1 only for 6MSM; the others get image 0 twice (a valid descriptor).
  VkImageView first = t.moment_mip0(f.channel, 0), second = images > 1 ? t.moment_mip0(f.channel, 1) : first;
  ImagePassPush push{glm::ivec4(t.config.shadow_size, t.config.shadow_size, 0, 0)};
  uint32_t groups = vk::groupCount(uint32_t(t.config.shadow_size), 8);
  vk::dispatch(f.cmd, program_, groups, groups, 1,
               {vk::Descriptor(f.uniforms),
                vk::Descriptor(t.shadow_depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler),
                vk::Descriptor(first, VK_IMAGE_LAYOUT_GENERAL), vk::Descriptor(second, VK_IMAGE_LAYOUT_GENERAL)},
               push);
  vk::pipelineBarrier(f.cmd, vk::memoryBarrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                                                   VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                                   VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                               VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT |
                                                   VK_ACCESS_2_TRANSFER_WRITE_BIT));
}

} // namespace msm::render
