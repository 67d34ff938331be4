#include "pass.h"

#include "msm/techniques.h"

namespace msm::render {

ImageSpec moment_image_spec(const FrameConfig& config, int i) {
  return {.format = config.formats()[size_t(i)],
          .width = uint32_t(config.shadow_size),
          // CSSM: its tiles stacked along y (cssm.h).
          .height = uint32_t(config.shadow_size * msm_technique_tiles(config.technique->id)),
          .mips = config.mip_levels,
          .layers = uint32_t(config.lights),
          // The renderer's Intermediates (renderer_internals.h) reads the resolved and the filtered moments back.
          .extra_usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT};
}

void MomentResolvePass::prepare(const PassResources& r) {
  const FrameConfig& config = config_;
  program_ = &r.programs.compute(config.msaa == 1 ? "moment_resolve_1x.comp" : "moment_resolve.comp",
                                 vk::bindings_at({{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                                  {MSM_BINDING_RESOLVE_DEPTH, vk::Binding::sampled_image},
                                                  {MSM_BINDING_RESOLVE_MOMENTS0, vk::Binding::storage_image},
                                                  {MSM_BINDING_RESOLVE_MOMENTS1, vk::Binding::storage_image},
                                                  {MSM_BINDING_RESOLVE_BACK_DEPTH, vk::Binding::sampled_image}}),
                                 sizeof(ImagePassPush),
                                 {{MSM_SPEC_TECHNIQUE, uint32_t(config.technique->id)},
                                  {MSM_SPEC_SPLIT_RG, config.split_rg() ? 1u : 0u},
                                  {MSM_SPEC_FRONT_BACK, config.front_back ? 1u : 0u}});
}

void MomentResolvePass::reflect(PassBuilder& b) const {
  b.read(kShadowDepth, use::sampled(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT));
  if (config_.front_back) b.read(kShadowDepthBack, use::sampled(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT));
  for (int i = 0; i < config_.moment_images(); ++i)
    b.create(moment_image(0, i), moment_image_spec(config_, i), use::compute_general());
}

void MomentResolvePass::execute(const PassContext& c) const {
  const GraphImage& depth = c.image(kShadowDepth);
  // Without front_back the shader reads no back-face map: the front one fills its binding.
  const GraphImage& back = c.image(config_.front_back ? kShadowDepthBack : kShadowDepth);
  int images = config_.moment_images();
  ImagePassPush push{glm::ivec4(config_.shadow_size, config_.shadow_size, 0, 0)};
  uint32_t groups = vk::group_count(uint32_t(config_.shadow_size), 8);
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    // The shader writes image 1 only for 6MSM and split RG; the others get image 0 twice.
    VkImageView first = c.image(moment_image(0, 0)).layer_mip0_views[size_t(l)];
    VkImageView second = images > 1 ? VkImageView(c.image(moment_image(0, 1)).layer_mip0_views[size_t(l)]) : first;
    vk::dispatch(
        c.cmd, *program_, groups, groups, 1,
        {{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
         {MSM_BINDING_RESOLVE_DEPTH, vk::Descriptor(depth.layer_views[size_t(l)],
                                                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, c.frame.point_sampler)},
         {MSM_BINDING_RESOLVE_MOMENTS0, vk::Descriptor(first, VK_IMAGE_LAYOUT_GENERAL)},
         {MSM_BINDING_RESOLVE_MOMENTS1, vk::Descriptor(second, VK_IMAGE_LAYOUT_GENERAL)},
         {MSM_BINDING_RESOLVE_BACK_DEPTH,
          vk::Descriptor(back.layer_views[size_t(l)], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                         c.frame.point_sampler)}},
        push);
    c.end_light();
  }
}

void ChannelCopyPass::reflect(PassBuilder& b) const {
  for (int i = 0; i < config_.moment_images(); ++i) {
    // An ordered use of channel 0 (a modifier in the graph's terms, though it only reads): the copy
    // takes the opaque moments before the red channel's translucent blend.
    b.modify(moment_image(0, i), use::transfer_source());
    for (int channel = 1; channel < config_.channels(); ++channel)
      b.create(moment_image(channel, i), moment_image_spec(config_, i), use::transfer_destination());
  }
}

void ChannelCopyPass::execute(const PassContext& c) const {
  for (int i = 0; i < config_.moment_images(); ++i)
    for (int channel = 1; channel < config_.channels(); ++channel) {
      constexpr VkImageAspectFlags color = VK_IMAGE_ASPECT_COLOR_BIT;
      uint32_t layers = uint32_t(config_.lights);
      VkImageCopy2 region{.sType = VK_STRUCTURE_TYPE_IMAGE_COPY_2,
                          .srcSubresource = {color, 0, 0, layers},
                          .dstSubresource = {color, 0, 0, layers},
                          .extent = {uint32_t(config_.shadow_size), uint32_t(config_.shadow_size), 1}};
      VkCopyImageInfo2 copy{.sType = VK_STRUCTURE_TYPE_COPY_IMAGE_INFO_2,
                            .srcImage = c.image(moment_image(0, i)).image.handle(),
                            .srcImageLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            .dstImage = c.image(moment_image(channel, i)).image.handle(),
                            .dstImageLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                            .regionCount = 1,
                            .pRegions = &region};
      vkCmdCopyImage2(c.cmd, &copy);
    }
}

} // namespace msm::render
