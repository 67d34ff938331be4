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
  std::string fragment = depth_based                        ? (msaa == 1 ? "shading_depth_1x.frag" : "shading_depth.frag")
                         : technique.id == MSM_TECH_NL64 ? "shading_nl64.frag"
                         : technique.id == MSM_TECH_NL32 ? "shading_nl32.frag"
                                                         : "shading_moments.frag";
  vk::GraphicsDesc d{.name = std::string("shading ") + std::string(technique.name),
                     .vertexShader = "shading.vert",
                     .fragmentShader = fragment,
                     .bindings = {vk::Binding::UniformBuffer, vk::Binding::SampledImage, vk::Binding::SampledImage},
                     .pushConstantSize = sizeof(ObjectPush),
                     .vertexStride = sizeof(Vertex),
                     .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                    {1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
                                    {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                     .colorFormats = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R32G32_SFLOAT},
                     .depthFormat = VK_FORMAT_D32_SFLOAT,
                     .constants = {{0, uint32_t(technique.id)}}};
  if (!depth_based) { // second moment image, blue noise
    d.bindings.push_back(vk::Binding::SampledImage);
    d.bindings.push_back(vk::Binding::SampledImage);
  }
  return d;
}

} // namespace

ShadingPass::ShadingPass(const vk::Context& ctx, const Technique& technique, int msaa)
    : program_(vk::createGraphicsProgram(ctx, shading_desc(technique, msaa))),
      depth_based_(msm_technique_is_depth_based(technique.id)),
      nonlinear_(msm_technique_is_nonlinear(technique.id)) {}

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
                               : vk::Descriptor(t.moments[0], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                                nonlinear_ ? t.point_sampler : t.moment_sampler);
  // The second image of 6MSM; the others bind something valid of the declared type (float).
  vk::Descriptor second = t.config.moment_images() > 1
                              ? vk::Descriptor(t.moments[1], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.moment_sampler)
                          : nonlinear_ ? vk::Descriptor(f.scene.white.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                                        t.point_sampler)
                                       : shadow0;
  vk::Descriptor noise(f.blue_noise.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler);
  for (const Draw& d : f.scene.draws) {
    const vk::Image& texture = d.texture >= 0 ? f.scene.textures[size_t(d.texture)] : f.scene.white;
    vk::Descriptor albedo(texture.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, f.scene.texture_sampler);
    vkCmdSetCullMode(f.cmd, d.double_sided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT);
    if (depth_based_)
      vk::bindProgram(f.cmd, program_, {vk::Descriptor(f.uniforms), albedo, shadow0}, d.push);
    else
      vk::bindProgram(f.cmd, program_, {vk::Descriptor(f.uniforms), albedo, shadow0, second, noise}, d.push);
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
