#include "pass.h"

namespace msm::render {

void bind_scene(VkCommandBuffer cmd, const GpuScene& scene) {
  VkDeviceSize offset = 0;
  VkBuffer vertices = scene.vertices.handle();
  vkCmdBindVertexBuffers(cmd, 0, 1, &vertices, &offset);
  vkCmdBindIndexBuffer(cmd, scene.indices.handle(), 0, VK_INDEX_TYPE_UINT32);
}

void ShadowDepthPass::prepare(const PassResources& r) {
  const FrameConfig& config = config_;
  program_ = &r.programs.graphics({.name = "shadow_depth",
                                   .vertex_shader = "shadow_depth.vert",
                                   .bindings = {vk::Binding::uniform_buffer, vk::Binding::storage_buffer},
                                   .push_constant_size = sizeof(ObjectPush),
                                   .vertex_stride = sizeof(Vertex),
                                   .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0}},
                                   .depth_format = VK_FORMAT_D16_UNORM,
                                   .samples = VkSampleCountFlagBits(config.msaa),
                                   // casters in front of the fitted near plane still cast
                                   .depth_clamp = true});
}

void ShadowDepthPass::reflect(PassBuilder& b) const {
  // Single-sampled depth is read back by copy (Renderer::Intermediates), MSAA depth by a shader.
  b.create(kShadowDepth,
           {.format = VK_FORMAT_D16_UNORM,
            .width = uint32_t(config_.shadow_size),
            .height = uint32_t(config_.shadow_size),
            .layers = uint32_t(config_.lights),
            .samples = VkSampleCountFlagBits(config_.msaa),
            .extra_usage = VkImageUsageFlags(config_.msaa == 1 ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0)},
           use::depth_attachment());
}

void ShadowDepthPass::execute(const PassContext& c) const {
  const GraphImage& depth = c.image(kShadowDepth);
  VkExtent2D size{uint32_t(config_.shadow_size), uint32_t(config_.shadow_size)};
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    vk::begin_rendering(c.cmd, size, {}, vk::DepthAttachment{depth.layer_views[size_t(l)], 1.0f});
    vk::set_viewport_scissor(c.cmd, size);
    vkCmdSetCullMode(c.cmd, VK_CULL_MODE_NONE); // both sides cast: thin walls, planes, open meshes
    bind_scene(c.cmd, c.frame.scene);
    ObjectPush push{};
    push.light.x = l;
    vk::bind_program(c.cmd, *program_, {vk::Descriptor(c.frame.uniforms), vk::Descriptor(c.frame.lights)}, push);
    for (const Draw& d : c.frame.scene.draws) vkCmdDrawIndexed(c.cmd, d.index_count, 1, d.first_index, 0, 0);
    vkCmdEndRendering(c.cmd);
    c.end_light();
  }
}

} // namespace msm::render
