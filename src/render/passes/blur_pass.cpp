#include "pass.h"

namespace msm::render {

const PassDecl& BlurPass::decl() {
  static const PassDecl d{"blur", {"moments", "frame.filter_weights"}, {"moments"}};
  return d;
}

BlurPass::BlurPass(const vk::Context& ctx)
    : program_(vk::create_program(ctx, "blur.comp",
                                  {vk::Binding::uniform_buffer, vk::Binding::sampled_image, vk::Binding::storage_image},
                                  sizeof(ImagePassPush))) {}

void BlurPass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  int size = t.config.shadow_size;
  uint32_t groups = vk::group_count(uint32_t(size), 8);
  VkImageLayout general = VK_IMAGE_LAYOUT_GENERAL;
  for (int i = 0; i < t.config.moment_images(); ++i) {
    VkImageView moments = t.moment_mip0(f.channel, i);
    const vk::Image& temp = t.blur_temp[size_t(i)];
    vk::pipeline_barrier(f.cmd, vk::image_barrier(temp.handle(), VK_IMAGE_ASPECT_COLOR_BIT,
                                                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED,
                                                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, general));
    vk::dispatch(f.cmd, program_, groups, groups, 1,
                 {vk::Descriptor(f.uniforms), vk::Descriptor(moments, general, t.point_sampler), vk::Descriptor(temp)},
                 ImagePassPush{glm::ivec4(size, size, 0, 0)});
    vk::pipeline_barrier(
        f.cmd, vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                  VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT));
    vk::dispatch(
        f.cmd, program_, groups, groups, 1,
        {vk::Descriptor(f.uniforms), vk::Descriptor(temp, general, t.point_sampler), vk::Descriptor(moments, general)},
        ImagePassPush{glm::ivec4(size, size, 1, 0)});
  }
  vk::pipeline_barrier(f.cmd,
                       vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                          VK_PIPELINE_STAGE_2_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                                              VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                          VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT));
}

} // namespace msm::render
