#include "pass.h"

#include "msm/techniques.h"

namespace msm::render {

const PassDecl& ShadingPass::decl() {
  static const PassDecl d{"shading", {"scene", "shadow_depth | moments", "frame"}, {"color", "shadow_buffer"}};
  return d;
}

namespace {

vk::GraphicsDesc shading_desc(const Technique& technique, int msaa) {
  bool depth_based = msm_technique_is_depth_based(technique.id);
  vk::GraphicsDesc d{.name = std::string("shading ") + std::string(technique.name),
                     .vertexShader = "shading.vert",
                     .fragmentShader = depth_based ? (msaa == 1 ? "shading_depth_1x.frag" : "shading_depth.frag")
                                                   : "shading_moments.frag",
                     .bindings = {vk::Binding::UniformBuffer, vk::Binding::SampledImage, vk::Binding::SampledImage},
                     .pushConstantSize = sizeof(ObjectPush),
                     .vertexStride = sizeof(Vertex),
                     .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                    {1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
                                    {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                     .colorFormats = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R32G32_SFLOAT},
                     .depthFormat = VK_FORMAT_D32_SFLOAT,
                     .constants = {{0, uint32_t(technique.id)}}};
  if (!depth_based) d.bindings.push_back(vk::Binding::SampledImage);
  return d;
}

} // namespace

ShadingPass::ShadingPass(const vk::Context& ctx, const Technique& technique, int msaa)
    : program_(vk::createGraphicsProgram(ctx, shading_desc(technique, msaa))),
      depth_based_(msm_technique_is_depth_based(technique.id)) {}

void ShadingPass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  auto to_attachment = [&](const vk::Image& image, VkPipelineStageFlags2 stage, VkAccessFlags2 access,
                           VkImageLayout layout) {
    vk::pipelineBarrier(f.cmd, vk::imageBarrier(image.handle(), image.aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0,
                                                VK_IMAGE_LAYOUT_UNDEFINED, stage, access, layout));
  };
  VkPipelineStageFlags2 color_stage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
  to_attachment(t.color, color_stage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  to_attachment(t.shadow_buffer, color_stage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
  to_attachment(t.camera_depth,
                VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);

  VkExtent2D size = extent(t.color);
  // The background: visibility 1 (nothing to shadow), coverage 0. The sky colour is linear.
  VkClearColorValue sky{{0.55f, 0.65f, 0.8f, 1.0f}}, lit{{1.0f, 0.0f, 0.0f, 0.0f}};
  vk::beginRendering(f.cmd, size, {{t.color.view(), sky}, {t.shadow_buffer.view(), lit}},
                     vk::DepthAttachment{t.camera_depth.view(), 1.0f});
  vk::setViewportScissor(f.cmd, size);
  VkDeviceSize offset = 0;
  VkBuffer vertices = f.scene.vertices.handle();
  vkCmdBindVertexBuffers(f.cmd, 0, 1, &vertices, &offset);
  vkCmdBindIndexBuffer(f.cmd, f.scene.indices.handle(), 0, VK_INDEX_TYPE_UINT32);

  vk::Descriptor shadow0 = depth_based_
                               ? vk::Descriptor(t.shadow_depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                                t.point_sampler)
                               : vk::Descriptor(t.moments[0], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.moment_sampler);
  const vk::Image& second = t.config.moment_images() > 1 ? t.moments[1] : t.moments[0];
  for (const Draw& d : f.scene.draws) {
    const vk::Image& texture = d.texture >= 0 ? f.scene.textures[size_t(d.texture)] : f.scene.white;
    vk::Descriptor albedo(texture.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, f.scene.texture_sampler);
    vkCmdSetCullMode(f.cmd, d.double_sided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT);
    if (depth_based_)
      vk::bindProgram(f.cmd, program_, {vk::Descriptor(f.uniforms), albedo, shadow0}, d.push);
    else
      vk::bindProgram(f.cmd, program_,
                      {vk::Descriptor(f.uniforms), albedo, shadow0,
                       vk::Descriptor(second, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.moment_sampler)},
                      d.push);
    vkCmdDrawIndexed(f.cmd, d.index_count, 1, d.first_index, 0, 0);
  }
  vkCmdEndRendering(f.cmd);
  for (const vk::Image* image : {&t.color, &t.shadow_buffer})
    vk::pipelineBarrier(f.cmd, vk::imageBarrier(image->handle(), image->aspect(), color_stage,
                                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                                VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL));
}

} // namespace msm::render
