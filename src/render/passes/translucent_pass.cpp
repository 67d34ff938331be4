#include "pass.h"

#include "msm/techniques.h"

#include <algorithm>

namespace msm::render {
namespace {

vk::GraphicsDesc translucent_desc(const FrameConfig& config) {
  bool split_rg = config.split_rg();
  std::string fragment = std::string(split_rg ? "translucent_moments2" : "translucent_moments") +
                         (config.msaa == 1 ? "_1x.frag" : ".frag");
  vk::GraphicsDesc d{
      .name = std::string("translucent ") + std::string(config.technique->name),
      .vertex_shader = "translucent.vert",
      .fragment_shader = fragment,
      .bindings = vk::bindings_at({{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                   {MSM_BINDING_TRANSLUCENT_OPACITY, vk::Binding::sampled_image},
                                   {MSM_BINDING_TRANSLUCENT_DEPTH, vk::Binding::sampled_image},
                                   {MSM_BINDING_TRANSLUCENT_LIGHTS, vk::Binding::storage_buffer}}),
      .push_constant_size = sizeof(ObjectPush),
      .vertex_stride = sizeof(Vertex),
      .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                     {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
      .color_formats = {config.formats()[0]},
      .alpha_blend = true,
      .constants = {{MSM_SPEC_TECHNIQUE, uint32_t(config.technique->id)}, {MSM_SPEC_SPLIT_RG, split_rg ? 1u : 0u}}};
  if (split_rg) d.color_formats.push_back(config.formats()[1]);
  return d;
}

// The translucent draws far to near from layer l's light: along a directional light's travel, by
// the distance from a spot or point light (per object, by the centre of its bounds). The scene
// sorted them, and each one's triangles, for its first layer's light (gpu_scene.h); the objects are
// sorted here for every layer (a few draws).
std::vector<const Draw*> back_to_front(const GpuScene& scene, const LightUniforms& light) {
  std::vector<const Draw*> order;
  order.reserve(scene.translucent.size());
  for (const Draw& d : scene.translucent) order.push_back(&d);
  const bool local = light.spot_position.w > 0.0f;
  const glm::vec3 travel = -glm::vec3(light.towards_light), position(light.spot_position);
  auto farness = [&](const Draw* d) {
    return local ? glm::distance(d->center, position) : glm::dot(d->center, travel);
  };
  std::stable_sort(order.begin(), order.end(), [&](const Draw* a, const Draw* b) { return farness(a) > farness(b); });
  return order;
}

} // namespace

void TranslucentPass::prepare(const PassResources& r) { program_ = &r.programs.graphics(translucent_desc(config_)); }

void TranslucentPass::reflect(PassBuilder& b) const {
  b.read(kShadowDepth, use::sampled(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT));
  for (int i = 0; i < config_.moment_images(); ++i)
    b.modify(moment_image(channel_, i), use::color_attachment_general());
}

void TranslucentPass::execute(const PassContext& c) const {
  const GraphImage& depth = c.image(kShadowDepth);
  VkExtent2D size{uint32_t(config_.shadow_size), uint32_t(config_.shadow_size)};
  const GpuScene& scene = c.frame.scene;
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    std::vector<vk::ColorAttachment> targets;
    targets.reserve(size_t(config_.moment_images()));
    for (int i = 0; i < config_.moment_images(); ++i)
      targets.push_back({.view = c.image(moment_image(channel_, i)).layer_mip0_views[size_t(l)],
                         .load = true,
                         .layout = VK_IMAGE_LAYOUT_GENERAL});
    vk::begin_rendering(c.cmd, size, targets);
    vk::set_viewport_scissor(c.cmd, size);
    vkCmdSetCullMode(c.cmd, VK_CULL_MODE_NONE);
    bind_scene(c.cmd, scene);
    vk::Descriptor depth_samples(depth.layer_views[size_t(l)], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                 c.frame.point_sampler);
    for (const Draw* d : back_to_front(scene, c.frame.light_data[size_t(l)])) {
      ObjectPush push = d->push;
      push.flags.w = config_.coloured ? channel_ : -1; // the channel whose opacity to blend
      push.light.x = l;
      const vk::Image& opacity =
          d->opacity_texture >= 0 ? scene.opacity_textures[size_t(d->opacity_texture)] : scene.white;
      vk::bind_program(
          c.cmd, *program_,
          {{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
           {MSM_BINDING_TRANSLUCENT_OPACITY,
            vk::Descriptor(opacity.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, scene.texture_sampler)},
           {MSM_BINDING_TRANSLUCENT_DEPTH, depth_samples},
           {MSM_BINDING_TRANSLUCENT_LIGHTS, vk::Descriptor(c.frame.lights)}},
          push);
      vkCmdDrawIndexed(c.cmd, d->index_count, 1, d->first_index, 0, 0);
    }
    vkCmdEndRendering(c.cmd);
    c.end_light();
  }
}

} // namespace msm::render
