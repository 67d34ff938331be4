#include "pass.h"

#include <fmt/format.h>

namespace msm::render {

void BlurPass::prepare(const PassResources& r) {
  program_ = &r.programs.compute("blur.comp",
                                 {vk::Binding::uniform_buffer, vk::Binding::sampled_image, vk::Binding::storage_image},
                                 sizeof(ImagePassPush));
}

namespace {
std::string temp_name(int channel, int i) { return fmt::format("blur_temp{}.{}", i, channel); }
} // namespace

void BlurPass::reflect(PassBuilder& b) const {
  for (int i = 0; i < config_.moment_images(); ++i) {
    b.modify(moment_image(channel_, i), use::compute_general());
    // Between the two directions, in float: one layer, reused light after light.
    b.scratch(temp_name(channel_, i), {.format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                       .width = uint32_t(config_.shadow_size),
                                       .height = uint32_t(config_.shadow_size),
                                       .extra_usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
  }
}

void BlurPass::execute(const PassContext& c) const {
  int size = config_.shadow_size;
  uint32_t groups = vk::group_count(uint32_t(size), 8);
  constexpr VkImageLayout general = VK_IMAGE_LAYOUT_GENERAL;
  constexpr VkPipelineStageFlags2 compute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    for (int i = 0; i < config_.moment_images(); ++i) {
      VkImageView moments = c.image(moment_image(channel_, i)).layer_mip0_views[size_t(l)];
      const GraphImage& temp = c.image(temp_name(channel_, i));
      // The scratch image's earlier contents (the previous light's) are not needed.
      vk::pipeline_barrier(c.cmd, vk::image_barrier(temp.image.handle(), VK_IMAGE_ASPECT_COLOR_BIT, compute,
                                                    VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                                                    compute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, general));
      vk::dispatch(c.cmd, *program_, groups, groups, 1,
                   {vk::Descriptor(c.frame.uniforms), vk::Descriptor(moments, general, c.frame.point_sampler),
                    vk::Descriptor(temp.layer_views[0], general)},
                   ImagePassPush{glm::ivec4(size, size, 0, 0)});
      vk::pipeline_barrier(
          c.cmd,
          vk::memory_barrier(compute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                             compute, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT));
      vk::dispatch(c.cmd, *program_, groups, groups, 1,
                   {vk::Descriptor(c.frame.uniforms),
                    vk::Descriptor(temp.layer_views[0], general, c.frame.point_sampler),
                    vk::Descriptor(moments, general)},
                   ImagePassPush{glm::ivec4(size, size, 1, 0)});
    }
    c.end_light();
  }
}

} // namespace msm::render
