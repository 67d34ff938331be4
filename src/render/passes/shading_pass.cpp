#include "pass.h"

#include "msm/techniques.h"

#include <algorithm>

namespace msm::render {

const PassDecl& ShadingPass::decl() {
  static const PassDecl d{"shading", {"scene", "shadow_depth | moments", "frame"}, {"color", "shadow_buffer"}};
  return d;
}

namespace {

vk::GraphicsDesc shading_desc(const Technique& technique, int msaa, bool split_rg, bool coloured, bool translucent) {
  bool depth_based = msm_technique_is_depth_based(technique.id);
  std::string fragment = depth_based                     ? (msaa == 1 ? "shading_depth_1x.frag" : "shading_depth.frag")
                         : technique.id == MSM_TECH_NL64 ? "shading_nl64.frag"
                         : technique.id == MSM_TECH_NL32 ? "shading_nl32.frag"
                         : msm_technique_is_soft(technique.id) ? "shading_soft.frag"
                         : coloured                            ? "shading_moments_rgb.frag"
                                                               : "shading_moments.frag";
  vk::GraphicsDesc d{.name = std::string("shading ") + std::string(technique.name),
                     .vertex_shader = "shading.vert",
                     .fragment_shader = fragment,
                     .bindings = {vk::Binding::uniform_buffer, vk::Binding::sampled_image, vk::Binding::sampled_image},
                     .push_constant_size = sizeof(ObjectPush),
                     .vertex_stride = sizeof(Vertex),
                     .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                    {1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
                                    {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                     .color_formats = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R32G32B32A32_SFLOAT},
                     .depth_format = VK_FORMAT_D32_SFLOAT,
                     .depth_write = !translucent,
                     .constants = {{0, uint32_t(technique.id)}, {3, split_rg ? 1u : 0u}}};
  // Second moment image, blue noise, opacity texture, then the green and blue channels' moment
  // images (coloured translucency); the depth-based shaders use neither the second image nor the
  // noise; the layout is the same for every technique.
  for (int i = 0; i < 7; ++i) d.bindings.push_back(vk::Binding::sampled_image);
  if (translucent) { // over the opaque image; the shadow buffer keeps the opaque surface's
    d.name += " (translucent)";
    d.alpha_blend = true;
    d.color_write_masks = {VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT, 0};
  }
  return d;
}

} // namespace

ShadingPass::ShadingPass(const vk::Context& ctx, const Technique& technique, int msaa, bool split_rg, bool coloured)
    : program_(vk::create_graphics_program(ctx, shading_desc(technique, msaa, split_rg, coloured, false))),
      translucent_program_(vk::create_graphics_program(ctx, shading_desc(technique, msaa, split_rg, coloured, true))),
      depth_based_(msm_technique_is_depth_based(technique.id)), nonlinear_(msm_technique_is_nonlinear(technique.id)),
      soft_(msm_technique_is_soft(technique.id)) {}

void ShadingPass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  auto to_attachment = [&](const vk::Image& image, VkPipelineStageFlags2 stage, VkAccessFlags2 access,
                           VkImageLayout layout) {
    vk::pipeline_barrier(f.cmd, vk::image_barrier(image.handle(), image.aspect(), VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                                  0, VK_IMAGE_LAYOUT_UNDEFINED, stage, access, layout));
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
  VkClearColorValue sky{{0.55f, 0.65f, 0.8f, 1.0f}}, lit{{1.0f, 1.0f, 1.0f, 0.0f}};
  vk::begin_rendering(f.cmd, size, {{t.color.view(), sky}, {t.shadow_buffer.view(), lit}},
                      vk::DepthAttachment{t.camera_depth.view(), 1.0f});
  vk::set_viewport_scissor(f.cmd, size);
  VkDeviceSize offset = 0;
  VkBuffer vertices = f.scene.vertices.handle();
  vkCmdBindVertexBuffers(f.cmd, 0, 1, &vertices, &offset);
  vkCmdBindIndexBuffer(f.cmd, f.scene.indices.handle(), 0, VK_INDEX_TYPE_UINT32);

  vk::Descriptor shadow0 =
      soft_          ? vk::Descriptor(t.sat_tables[0], VK_IMAGE_LAYOUT_GENERAL, t.point_sampler)
      : depth_based_ ? vk::Descriptor(t.shadow_depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler)
                     : vk::Descriptor(t.moments[0], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                      nonlinear_ ? t.point_sampler : t.moment_sampler);
  // The second image of 6MSM (the second table of mssm6); the others bind something valid of the
  // declared type (float; unsigned for the tables).
  bool two = t.config.moment_images() > 1;
  vk::Descriptor second =
      soft_        ? vk::Descriptor(t.sat_tables[two ? 1 : 0], VK_IMAGE_LAYOUT_GENERAL, t.point_sampler)
      : two        ? vk::Descriptor(t.moments[1], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.moment_sampler)
      : nonlinear_ ? vk::Descriptor(f.scene.white.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler)
                   : shadow0;
  vk::Descriptor noise(f.blue_noise.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler);
  if (depth_based_)
    second = vk::Descriptor(f.scene.white.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler);
  // The green and blue channels' moment images where the frame has them, else the first set.
  std::array<vk::Descriptor, 4> colour{shadow0, second, shadow0, second};
  if (t.config.coloured)
    for (int c = 1; c < 3; ++c)
      for (int i = 0; i < 2; ++i) {
        int image = std::min(i, t.config.moment_images() - 1);
        colour[size_t(2 * (c - 1) + i)] =
            vk::Descriptor(t.moment_image(c, image), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.moment_sampler);
      }
  auto draw = [&](const vk::Program& program, const Draw& d) {
    const vk::Image& texture = d.texture >= 0 ? f.scene.textures[size_t(d.texture)] : f.scene.white;
    const vk::Image& opacity =
        d.opacity_texture >= 0 ? f.scene.opacity_textures[size_t(d.opacity_texture)] : f.scene.white;
    vk::Descriptor albedo(texture.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, f.scene.texture_sampler);
    vk::Descriptor alpha(opacity.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, f.scene.texture_sampler);
    vkCmdSetCullMode(f.cmd, d.double_sided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT);
    vk::bind_program(
        f.cmd, program,
        {vk::Descriptor(f.uniforms), albedo, shadow0, second, noise, alpha, colour[0], colour[1], colour[2], colour[3]},
        d.push);
    vkCmdDrawIndexed(f.cmd, d.index_count, 1, d.first_index, 0, 0);
  };
  for (const Draw& d : f.scene.draws) draw(program_, d);
  // Translucent surfaces over the opaque image, far to near from the camera (per object).
  std::vector<const Draw*> order;
  for (const Draw& d : f.scene.translucent) order.push_back(&d);
  std::stable_sort(order.begin(), order.end(), [&](const Draw* a, const Draw* b) {
    return glm::distance(a->center, f.camera_position) > glm::distance(b->center, f.camera_position);
  });
  for (const Draw* d : order) draw(translucent_program_, *d);
  vkCmdEndRendering(f.cmd);
  for (const vk::Image* image : {&t.color, &t.shadow_buffer})
    vk::pipeline_barrier(
        f.cmd, vk::image_barrier(image->handle(), image->aspect(), color_stage, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                 VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL));
}

} // namespace msm::render
