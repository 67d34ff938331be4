#include "pass.h"

namespace msm::render {

const PassDecl& ShadowDepthPass::decl() {
  static const PassDecl d{"shadow_depth", {"scene", "frame.light_view_projection"}, {"shadow_depth"}};
  return d;
}

ShadowDepthPass::ShadowDepthPass(const vk::Context& ctx, int msaa)
    : program_(vk::create_graphics_program(ctx, {.name = "shadow_depth",
                                                 .vertex_shader = "shadow_depth.vert",
                                                 .bindings = {vk::Binding::uniform_buffer},
                                                 .vertex_stride = sizeof(Vertex),
                                                 .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0}},
                                                 .depth_format = VK_FORMAT_D16_UNORM,
                                                 .samples = VkSampleCountFlagBits(msaa),
                                                 // casters in front of the fitted near plane still cast
                                                 .depth_clamp = true})),
      masked_program_(
          vk::create_graphics_program(ctx, {.name = "shadow_depth (alpha-tested)",
                                            .vertex_shader = "shadow_depth_masked.vert",
                                            .fragment_shader = "shadow_depth_masked.frag",
                                            .bindings = {vk::Binding::uniform_buffer, vk::Binding::sampled_image},
                                            .push_constant_size = sizeof(ObjectPush),
                                            .vertex_stride = sizeof(Vertex),
                                            .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                                           {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                                            .depth_format = VK_FORMAT_D16_UNORM,
                                            .samples = VkSampleCountFlagBits(msaa),
                                            .depth_clamp = true})) {}

void ShadowDepthPass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const vk::Image& depth = f.targets.shadow_depth;
  vk::pipeline_barrier(
      f.cmd, vk::image_barrier(
                 depth.handle(), depth.aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
                 VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL));
  vk::begin_rendering(f.cmd, extent(depth), {}, vk::DepthAttachment{depth.view(), 1.0f});
  vk::set_viewport_scissor(f.cmd, extent(depth));
  vkCmdSetCullMode(f.cmd, VK_CULL_MODE_NONE); // both sides cast: thin walls, planes, open meshes
  VkDeviceSize offset = 0;
  VkBuffer vertices = f.scene.vertices.handle();
  vkCmdBindVertexBuffers(f.cmd, 0, 1, &vertices, &offset);
  vkCmdBindIndexBuffer(f.cmd, f.scene.indices.handle(), 0, VK_INDEX_TYPE_UINT32);
  const vk::Program* bound = nullptr;
  for (const Draw& d : f.scene.draws) {
    if (d.masked) { // its own opacity texture and cutoff
      const vk::Image& opacity =
          d.opacity_texture >= 0 ? f.scene.opacity_textures[size_t(d.opacity_texture)] : f.scene.white;
      vk::bind_program(
          f.cmd, masked_program_,
          {vk::Descriptor(f.uniforms),
           vk::Descriptor(opacity.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, f.scene.texture_sampler)},
          d.push);
      bound = &masked_program_;
    } else if (bound != &program_) {
      vk::bind_program(f.cmd, program_, {vk::Descriptor(f.uniforms)});
      bound = &program_;
    }
    vkCmdDrawIndexed(f.cmd, d.index_count, 1, d.first_index, 0, 0);
  }
  vkCmdEndRendering(f.cmd);
  vk::pipeline_barrier(
      f.cmd, vk::image_barrier(depth.handle(), depth.aspect(), VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                               VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                   VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                               VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT,
                               VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL));
}

} // namespace msm::render
