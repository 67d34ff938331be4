#include "pass.h"

#include "msm/shading.h"
#include "msm/techniques.h"

#include <algorithm>

namespace msm::render {
namespace {

vk::GraphicsDesc shading_desc(const FrameConfig& config, bool translucent) {
  const Technique& technique = *config.technique;
  std::string fragment = msm_technique_is_depth_based(technique.id)
                             ? (config.msaa == 1 ? "shading_depth_1x.frag" : "shading_depth.frag")
                         : technique.id == MSM_TECH_NL64       ? "shading_nl64.frag"
                         : technique.id == MSM_TECH_NL32       ? "shading_nl32.frag"
                         : msm_technique_is_soft(technique.id) ? "shading_soft.frag"
                         : config.coloured                     ? "shading_moments_rgb.frag"
                                                               : "shading_moments.frag";
  vk::GraphicsDesc d{
      .name = std::string("shading ") + std::string(technique.name),
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
      .constants = {{0, uint32_t(technique.id)}, {3, config.split_rg() ? 1u : 0u}, {4, config.lights == 1 ? 1u : 0u}}};
  if (msm_technique_is_nonlinear(technique.id)) d.constants.push_back({9, config.nonlinear_bilinear ? 1u : 0u});
  // Scattering techniques: linear radiance for the scattering pass to composite and tone map.
  if (msm_technique_is_scattering(technique.id)) {
    d.color_formats[0] = VK_FORMAT_R16G16B16A16_SFLOAT;
    d.constants.push_back({5, 1u});
  }
  // Second moment image, blue noise, opacity texture, the green and blue channels' moment images
  // (coloured translucency), then the lights (binding 10); the same layout for every technique.
  for (int i = 0; i < 7; ++i) d.bindings.push_back(vk::Binding::sampled_image);
  d.bindings.push_back(vk::Binding::storage_buffer);
  if (translucent) { // over the opaque image; the shadow buffer keeps the opaque surface's
    d.name += " (translucent)";
    d.alpha_blend = true;
    d.color_write_masks = {VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT, 0};
  }
  return d;
}

} // namespace

void ShadingPass::prepare(const PassResources& r) {
  program_ = &r.programs.graphics(shading_desc(config_, false));
  translucent_program_ = &r.programs.graphics(shading_desc(config_, true));
}

void ShadingPass::reflect(PassBuilder& b) const {
  const VkPipelineStageFlags2 fragment = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
  int id = config_.technique->id;
  if (msm_technique_is_depth_based(id)) {
    b.read(kShadowDepth, use::sampled(fragment));
  } else if (msm_technique_is_soft(id)) {
    for (int i = 0; i < config_.moment_images(); ++i) b.read(sat_table(i), use::sampled(fragment));
  } else {
    for (int channel = 0; channel < config_.channels(); ++channel)
      for (int i = 0; i < config_.moment_images(); ++i) b.read(moment_image(channel, i), use::sampled(fragment));
  }
  uint32_t w = uint32_t(config_.width), h = uint32_t(config_.height);
  if (msm_technique_is_scattering(id))
    b.create(kSurfaceRadiance, {.format = VK_FORMAT_R16G16B16A16_SFLOAT, .width = w, .height = h},
             use::color_attachment());
  else
    b.create(kColor, {.format = VK_FORMAT_R8G8B8A8_SRGB, .width = w, .height = h}, use::color_attachment());
  b.create(kShadowBuffer, {.format = VK_FORMAT_R32G32B32A32_SFLOAT, .width = w, .height = h}, use::color_attachment());
  b.create(kCameraDepth, {.format = VK_FORMAT_D32_SFLOAT, .width = w, .height = h}, use::depth_attachment());
}

void ShadingPass::execute(const PassContext& c) const {
  const GpuScene& scene = c.frame.scene;
  int id = config_.technique->id;
  bool depth_based = msm_technique_is_depth_based(id), soft = msm_technique_is_soft(id),
       nonlinear = msm_technique_is_nonlinear(id);
  // Scattering techniques: the linear radiance (the sky's too), composited by the scattering pass.
  bool scatters = msm_technique_is_scattering(id);
  const GraphImage& color = c.image(scatters ? kSurfaceRadiance : kColor);
  const GraphImage& shadow_buffer = c.image(kShadowBuffer);
  VkExtent2D size{uint32_t(config_.width), uint32_t(config_.height)};
  // The background: visibility 1 (nothing to shadow), coverage 0. The sky colour is linear.
  glm::vec3 sky_radiance = scatters ? glm::vec3(c.frame.scattering.sky) : MSM_SKY_RADIANCE; // shown the same
  VkClearColorValue sky{{sky_radiance.r, sky_radiance.g, sky_radiance.b, 1.0f}}, lit{{1.0f, 1.0f, 1.0f, 0.0f}};
  vk::begin_rendering(c.cmd, size, {{color.layer_views[0], sky}, {shadow_buffer.layer_views[0], lit}},
                      vk::DepthAttachment{c.image(kCameraDepth).layer_views[0], 1.0f});
  vk::set_viewport_scissor(c.cmd, size);
  bind_scene(c.cmd, scene);

  const VkImageLayout read_only = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  auto array_of = [&](const std::string& name, VkSampler sampler) {
    return vk::Descriptor(c.image(name).array_view, read_only, sampler);
  };
  VkSampler moment_sampler = nonlinear ? c.frame.point_sampler : c.frame.linear_sampler;
  vk::Descriptor white(scene.white.view(), read_only, c.frame.point_sampler);
  // Every shadow-map binding is an array (one layer per light); the unused ones get an image of the
  // declared kind.
  vk::Descriptor first = depth_based ? array_of(kShadowDepth, c.frame.point_sampler)
                         : soft      ? array_of(sat_table(0), c.frame.point_sampler)
                                     : array_of(moment_image(0, 0), moment_sampler);
  bool two = config_.moment_images() > 1;
  vk::Descriptor second = depth_based ? white
                          : nonlinear ? vk::Descriptor(scene.white_array, read_only, c.frame.point_sampler)
                          : !two      ? first
                          : soft      ? array_of(sat_table(1), c.frame.point_sampler)
                                      : array_of(moment_image(0, 1), moment_sampler);
  vk::Descriptor noise(c.frame.blue_noise.view(), read_only, c.frame.point_sampler);
  std::array<vk::Descriptor, 4> colour{first, second, first, second};
  if (config_.coloured)
    for (int channel = 1; channel < 3; ++channel)
      for (int i = 0; i < 2; ++i)
        colour[size_t(2 * (channel - 1) + i)] =
            array_of(moment_image(channel, std::min(i, config_.moment_images() - 1)), moment_sampler);
  auto draw = [&](const vk::Program& program, const Draw& d) {
    const vk::Image& texture = d.texture >= 0 ? scene.textures[size_t(d.texture)] : scene.white;
    const vk::Image& opacity = d.opacity_texture >= 0 ? scene.opacity_textures[size_t(d.opacity_texture)] : scene.white;
    vk::Descriptor albedo(texture.view(), read_only, scene.texture_sampler);
    vk::Descriptor alpha(opacity.view(), read_only, scene.texture_sampler);
    vkCmdSetCullMode(c.cmd, d.double_sided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT);
    vk::bind_program(c.cmd, program,
                     {vk::Descriptor(c.frame.uniforms), albedo, first, second, noise, alpha, colour[0], colour[1],
                      colour[2], colour[3], vk::Descriptor(c.frame.lights)},
                     d.push);
    vkCmdDrawIndexed(c.cmd, d.index_count, 1, d.first_index, 0, 0);
  };
  for (const Draw& d : scene.draws) draw(*program_, d);
  // Translucent surfaces over the opaque image, far to near from the camera (per object).
  std::vector<const Draw*> order;
  for (const Draw& d : scene.translucent) order.push_back(&d);
  std::stable_sort(order.begin(), order.end(), [&](const Draw* a, const Draw* b) {
    return glm::distance(a->center, c.frame.camera_position) > glm::distance(b->center, c.frame.camera_position);
  });
  for (const Draw* d : order) draw(*translucent_program_, *d);
  vkCmdEndRendering(c.cmd);
}

} // namespace msm::render
