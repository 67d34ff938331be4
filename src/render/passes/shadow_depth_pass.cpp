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
  program_ = &r.programs.graphics(
      {.name = "shadow_depth",
       .vertex_shader = "shadow_depth.vert",
       .bindings = vk::bindings_at({{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                    {MSM_BINDING_SHADOW_DEPTH_LIGHTS, vk::Binding::storage_buffer}}),
       .push_constant_size = sizeof(ObjectPush),
       .vertex_stride = sizeof(Vertex),
       .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0}},
       .depth_format = VK_FORMAT_D16_UNORM,
       .samples = VkSampleCountFlagBits(config.msaa),
       // casters in front of the fitted near plane still cast
       .depth_clamp = true});
  // The alpha-tested variant; the spot lights' pass has its bindings and state, and its own shaders.
  vk::GraphicsDesc masked{.name = "shadow_depth (alpha-tested)",
                          .vertex_shader = "shadow_depth_masked.vert",
                          .fragment_shader = "shadow_depth_masked.frag",
                          .bindings =
                              vk::bindings_at({{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                               {MSM_BINDING_SHADOW_DEPTH_MASKED_OPACITY, vk::Binding::sampled_image},
                                               {MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS, vk::Binding::storage_buffer}}),
                          .push_constant_size = sizeof(ObjectPush),
                          .vertex_stride = sizeof(Vertex),
                          .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                         {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                          .depth_format = VK_FORMAT_D16_UNORM,
                          .samples = VkSampleCountFlagBits(config.msaa),
                          .depth_clamp = true};
  masked_program_ = &r.programs.graphics(masked);
  if (config.local_light_layers() > 0) {
    vk::GraphicsDesc spot = masked;
    spot.name = "shadow_depth (spot)";
    spot.vertex_shader = "shadow_depth_spot.vert";
    spot.fragment_shader = "shadow_depth_spot.frag";
    spot_program_ = &r.programs.graphics(spot);
  }
}

void ShadowDepthPass::reflect(PassBuilder& b) const {
  // Single-sampled depth is read back by copy (Intermediates, renderer_internals.h), MSAA depth by a shader.
  b.create(back_ ? kShadowDepthBack : kShadowDepth,
           {.format = VK_FORMAT_D16_UNORM,
            .width = uint32_t(config_.shadow_size),
            .height = uint32_t(config_.shadow_size),
            .layers = uint32_t(config_.lights),
            .samples = VkSampleCountFlagBits(config_.msaa),
            .extra_usage = VkImageUsageFlags(config_.msaa == 1 ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0)},
           use::depth_attachment());
}

void ShadowDepthPass::execute(const PassContext& c) const {
  const GraphImage& depth = c.image(back_ ? kShadowDepthBack : kShadowDepth);
  VkExtent2D size{uint32_t(config_.shadow_size), uint32_t(config_.shadow_size)};
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    vk::begin_rendering(c.cmd, size, {}, vk::DepthAttachment{depth.layer_views[size_t(l)], 1.0f});
    vk::set_viewport_scissor(c.cmd, size);
    // Both sides cast: thin walls, planes, open meshes. The back-face map culls the faces towards
    // the light (counter-clockwise in the light's clip space, as the camera's front faces).
    vkCmdSetCullMode(c.cmd, VK_CULL_MODE_NONE);
    VkCullModeFlags cull = VK_CULL_MODE_NONE;
    bind_scene(c.cmd, c.frame.scene);
    const GpuScene& scene = c.frame.scene;
    const vk::Program* bound = nullptr;
    // The spot and point lights' layers follow the directional lights' (FrameConfig::spot_lights,
    // point_lights): each a perspective view of radial depth, a point light's one per cube face.
    const bool spot = l >= config_.lights - config_.local_light_layers();
    for (const Draw& d : scene.draws) {
      if (back_) {
        VkCullModeFlags want = d.double_sided ? VK_CULL_MODE_NONE : VK_CULL_MODE_FRONT_BIT;
        if (want != cull) vkCmdSetCullMode(c.cmd, want);
        cull = want;
      }
      if (d.masked || spot) { // its own opacity texture and cutoff
        const vk::Image& opacity =
            d.opacity_texture >= 0 ? scene.opacity_textures[size_t(d.opacity_texture)] : scene.white;
        ObjectPush push = d.push;
        push.light.x = l;
        const vk::Program* program = spot ? spot_program_ : masked_program_;
        vk::bind_program(
            c.cmd, *program,
            {{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
             {MSM_BINDING_SHADOW_DEPTH_MASKED_OPACITY,
              vk::Descriptor(opacity.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, scene.texture_sampler)},
             {MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS, vk::Descriptor(c.frame.lights)}},
            push);
        bound = program;
      } else if (bound != program_) {
        ObjectPush push{};
        push.light.x = l;
        vk::bind_program(c.cmd, *program_,
                         {{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
                          {MSM_BINDING_SHADOW_DEPTH_LIGHTS, vk::Descriptor(c.frame.lights)}},
                         push);
        bound = program_;
      }
      vkCmdDrawIndexed(c.cmd, d.index_count, 1, d.first_index, 0, 0);
    }
    vkCmdEndRendering(c.cmd);
    c.end_light();
  }
}

} // namespace msm::render
