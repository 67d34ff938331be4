#include "pass.h"

#include "msm/techniques.h"

namespace msm::render {

const PassDecl& TranslucentPass::decl() {
  static const PassDecl d{"translucent", {"scene.translucent", "shadow_depth", "moments"}, {"moments"}};
  return d;
}

namespace {

vk::GraphicsDesc translucent_desc(const Technique& technique, int msaa, bool split_rg,
                                  const std::array<int, 2>& formats) {
  std::string fragment =
      std::string(split_rg ? "translucent_moments2" : "translucent_moments") + (msaa == 1 ? "_1x.frag" : ".frag");
  vk::GraphicsDesc d{.name = std::string("translucent ") + std::string(technique.name),
                     .vertex_shader = "translucent.vert",
                     .fragment_shader = fragment,
                     .bindings = {vk::Binding::uniform_buffer, vk::Binding::sampled_image, vk::Binding::sampled_image},
                     .push_constant_size = sizeof(ObjectPush),
                     .vertex_stride = sizeof(Vertex),
                     .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                    {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                     .color_formats = {VkFormat(formats[0])},
                     .alpha_blend = true,
                     .constants = {{0, uint32_t(technique.id)}, {3, split_rg ? 1u : 0u}}};
  if (split_rg) d.color_formats.push_back(VkFormat(formats[1]));
  return d;
}

} // namespace

TranslucentPass::TranslucentPass(const vk::Context& ctx, const Technique& technique, int msaa, bool split_rg,
                                 const std::array<int, 2>& formats)
    : program_(vk::create_graphics_program(ctx, translucent_desc(technique, msaa, split_rg, formats))) {}

void TranslucentPass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  constexpr VkPipelineStageFlags2 color = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
  constexpr VkAccessFlags2 color_rw = VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
  vk::pipeline_barrier(f.cmd, vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                 VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, color, color_rw));
  std::vector<vk::ColorAttachment> targets;
  for (int i = 0; i < t.config.moment_images(); ++i)
    targets.push_back({.view = t.moment_mip0(f.channel, i), .load = true, .layout = VK_IMAGE_LAYOUT_GENERAL});
  VkExtent2D size{uint32_t(t.config.shadow_size), uint32_t(t.config.shadow_size)};
  vk::begin_rendering(f.cmd, size, targets);
  vk::set_viewport_scissor(f.cmd, size);
  vkCmdSetCullMode(f.cmd, VK_CULL_MODE_NONE);
  VkDeviceSize offset = 0;
  VkBuffer vertices = f.scene.vertices.handle();
  vkCmdBindVertexBuffers(f.cmd, 0, 1, &vertices, &offset);
  vkCmdBindIndexBuffer(f.cmd, f.scene.indices.handle(), 0, VK_INDEX_TYPE_UINT32);
  vk::Descriptor depth(t.shadow_depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler);
  for (const Draw& d : f.scene.translucent) {
    ObjectPush push = d.push;
    push.flags.w = t.config.coloured ? f.channel : -1; // the channel whose opacity to blend
    const vk::Image& opacity =
        d.opacity_texture >= 0 ? f.scene.opacity_textures[size_t(d.opacity_texture)] : f.scene.white;
    vk::bind_program(f.cmd, program_,
                     {vk::Descriptor(f.uniforms),
                      vk::Descriptor(opacity.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, f.scene.texture_sampler),
                      depth},
                     push);
    vkCmdDrawIndexed(f.cmd, d.index_count, 1, d.first_index, 0, 0);
  }
  vkCmdEndRendering(f.cmd);
  vk::pipeline_barrier(f.cmd, vk::memory_barrier(color, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                                                     VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                                     VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT));
}

} // namespace msm::render
