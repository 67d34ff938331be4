#include "pass.h"

namespace msm::render {
namespace {
constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
uint32_t size(const FrameConfig& c) { return uint32_t(c.shadow_size); } // the rectified map's side
} // namespace

void RectifyPass::prepare(const PassResources& r) {
  program_ = &r.programs.compute(config_.msaa == 1 ? "rectify_1x.comp" : "rectify.comp",
                                 {vk::Binding::uniform_buffer, vk::Binding::uniform_buffer, vk::Binding::storage_buffer,
                                  vk::Binding::sampled_image, vk::Binding::storage_image},
                                 0);
}

void RectifyPass::reflect(PassBuilder& b) const {
  b.read(kShadowDepth, use::sampled(kCompute));
  b.create(kRectified, {.format = VK_FORMAT_R32G32B32A32_SFLOAT, .width = size(config_), .height = size(config_)},
           use::compute_general());
}

void RectifyPass::execute(const PassContext& c) const {
  uint32_t groups = vk::group_count(size(config_), 8);
  vk::dispatch(c.cmd, *program_, groups, groups, 1,
               {vk::Descriptor(c.frame.uniforms), vk::Descriptor(*c.frame.rectification),
                vk::Descriptor(c.frame.lights),
                vk::Descriptor(c.image(kShadowDepth).layer_views[0], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                               c.frame.point_sampler), // the first light
                vk::Descriptor(c.image(kRectified).layer_views[0], VK_IMAGE_LAYOUT_GENERAL)});
}

void PrefixSumPass::prepare(const PassResources& r) {
  program_ = &r.programs.compute(
      "prefix_sums.comp", {vk::Binding::uniform_buffer, vk::Binding::sampled_image, vk::Binding::storage_image}, 0);
}

void PrefixSumPass::reflect(PassBuilder& b) const {
  b.read(kRectified, use::sampled(kCompute));
  b.create(kPrefixSums, {.format = VK_FORMAT_R16G16B16A16_UNORM, .width = size(config_), .height = size(config_)},
           use::compute_general());
}

void PrefixSumPass::execute(const PassContext& c) const {
  vk::dispatch(c.cmd, *program_, vk::group_count(size(config_), 8), 1, 1,
               {vk::Descriptor(*c.frame.rectification),
                vk::Descriptor(c.image(kRectified).layer_views[0], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                               c.frame.point_sampler),
                vk::Descriptor(c.image(kPrefixSums).layer_views[0], VK_IMAGE_LAYOUT_GENERAL)});
}

} // namespace msm::render
