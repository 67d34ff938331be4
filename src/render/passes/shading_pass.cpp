#include "pass.h"

#include "msm/shading.h"
#include "msm/techniques.h"

#include <fmt/format.h>

#include <algorithm>
#include <span>

namespace msm::render {
namespace {

// The pipelines of the shading: forward (opaque, or translucent blended over), and deferred shading's
// surfaces pass and full-screen pass.
enum class Stage { opaque, translucent, surfaces, deferred };

std::string fragment_shader(const FrameConfig& config, Stage stage) {
  if (stage == Stage::surfaces) return "surfaces.frag";
  bool deferred = stage == Stage::deferred;
  switch (config.technique->shading) {
  case ShadingVariant::depth:
    return std::string(deferred ? "shading_depth_deferred" : "shading_depth") +
           (config.msaa == 1 ? "_1x.frag" : ".frag");
  case ShadingVariant::soft: return deferred ? "shading_soft_deferred.frag" : "shading_soft.frag";
  case ShadingVariant::none: break;
  case ShadingVariant::moments:
  case ShadingVariant::nl64:
  case ShadingVariant::nl32:
    if (deferred) throw RenderError(fmt::format("{}: no deferred shading", config.technique->name));
    break;
  }
  switch (config.technique->shading) {
  case ShadingVariant::nl64: return "shading_nl64.frag";
  case ShadingVariant::nl32: return "shading_nl32.frag";
  case ShadingVariant::moments: return config.coloured ? "shading_moments_rgb.frag" : "shading_moments.frag";
  default: throw RenderError(fmt::format("{}: not rendered", config.technique->name));
  }
}

// The shading's layout, the same for every technique and stage (msm/render/bindings.h).
std::vector<vk::Binding> shading_bindings() {
  using B = vk::Binding;
  return vk::bindings_at({{MSM_BINDING_FRAME, B::uniform_buffer},
                          {MSM_BINDING_SHADING_ALBEDO_TEXTURE, B::sampled_image},
                          {MSM_BINDING_SHADING_SHADOW_MAP, B::sampled_image},
                          {MSM_BINDING_SHADING_SHADOW_MAP1, B::sampled_image},
                          {MSM_BINDING_SHADING_BLUE_NOISE, B::sampled_image},
                          {MSM_BINDING_SHADING_OPACITY_TEXTURE, B::sampled_image},
                          {MSM_BINDING_SHADING_GREEN_MOMENTS, B::sampled_image},
                          {MSM_BINDING_SHADING_GREEN_MOMENTS1, B::sampled_image},
                          {MSM_BINDING_SHADING_BLUE_MOMENTS, B::sampled_image},
                          {MSM_BINDING_SHADING_BLUE_MOMENTS1, B::sampled_image},
                          {MSM_BINDING_SHADING_LIGHTS, B::storage_buffer},
                          {MSM_BINDING_SHADING_SURFACE_POSITION, B::sampled_image},
                          {MSM_BINDING_SHADING_SURFACE_NORMAL, B::sampled_image},
                          {MSM_BINDING_SHADING_SURFACE_ALBEDO, B::sampled_image},
                          {MSM_BINDING_SHADING_SOFT_CLAMPS, B::storage_buffer},
                          {MSM_BINDING_SHADING_SURFACE_GEOMETRIC_NORMAL, B::sampled_image}});
}

vk::GraphicsDesc shading_desc(const FrameConfig& config, Stage stage) {
  const Technique& technique = *config.technique;
  vk::GraphicsDesc d{.name =
                         std::string(stage == Stage::surfaces ? "surfaces " : "shading ") + std::string(technique.name),
                     .vertex_shader = "shading.vert",
                     .fragment_shader = fragment_shader(config, stage),
                     .bindings = shading_bindings(),
                     .push_constant_size = sizeof(ObjectPush),
                     .vertex_stride = sizeof(Vertex),
                     .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                    {1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
                                    {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                     .color_formats = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R32G32B32A32_SFLOAT},
                     .depth_format = VK_FORMAT_D32_SFLOAT,
                     .depth_write = stage == Stage::opaque || stage == Stage::surfaces,
                     // What steers the shading's loops and branches is compiled in (frame.glsl, shading.glsl,
                     // shading_depth.glsl): the technique, the lights, the lookup, the MSAA samples, the PCF taps.
                     .constants = {{MSM_SPEC_TECHNIQUE, uint32_t(technique.id)},
                                   {MSM_SPEC_SPLIT_RG, config.split_rg() ? 1u : 0u},
                                   {MSM_SPEC_LIGHT_COUNT, uint32_t(config.lights)},
                                   {MSM_SPEC_DEPTH_SAMPLES, uint32_t(config.msaa)},
                                   {MSM_SPEC_PCF_TAPS, uint32_t(config.taps)},
                                   {MSM_SPEC_LOOKUP, uint32_t(config.lookup)},
                                   {MSM_SPEC_TEXTURED_DRAWS, config.textured_draws ? 1u : 0u},
                                   {MSM_SPEC_SUB_LIGHTS, config.sub_lights ? 1u : 0u},
                                   {MSM_SPEC_SPOT_LIGHTS, config.local_light_layers() > 0 ? 1u : 0u},
                                   {MSM_SPEC_CASCADES, config.cascades > 1 ? 1u : 0u}}};
  // Scattering techniques: linear radiance for the scattering pass to composite and tone map.
  if (technique.scatters()) {
    d.color_formats[0] = VK_FORMAT_R16G16B16A16_SFLOAT;
    d.constants.push_back({MSM_SPEC_LINEAR_RADIANCE, 1u});
  }
  if (stage == Stage::translucent) { // over the opaque image; the shadow buffer keeps the opaque surface's
    d.name += " (translucent)";
    d.alpha_blend = true;
    d.color_write_masks = {VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT, 0};
  } else if (stage == Stage::surfaces) { // position, normal, albedo, geometric normal: as the forward pass has them
    d.color_formats.assign(4, VK_FORMAT_R32G32B32A32_SFLOAT);
  } else if (stage == Stage::deferred) { // the surfaces (the surface bindings), a full-screen triangle
    d.name += " (deferred)";
    d.vertex_shader = "fullscreen.vert";
    d.vertex_stride = 0;
    d.attributes.clear();
    d.depth_compare = VK_COMPARE_OP_ALWAYS; // the translucent draws after it test against the surfaces
  }
  return d;
}

const VkImageLayout kReadOnly = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;

// A probe-lit scene's background (background.frag): a full-screen triangle at the far plane where
// no surface is, into the colour attachment only (the shadow buffer keeps visibility 1, coverage 0).
vk::GraphicsDesc background_desc(const FrameConfig& config) {
  bool linear = msm_technique_is_scattering(config.technique->id);
  return {.name = "background (probe)",
          .vertex_shader = "background.vert",
          .fragment_shader = "background.frag",
          .bindings = vk::bindings_at({{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                       {MSM_BINDING_BACKGROUND_PROBE, vk::Binding::sampled_image}}),
          .push_constant_size = sizeof(ScatteringPush),
          .color_formats = {linear ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R8G8B8A8_SRGB,
                            VK_FORMAT_R32G32B32A32_SFLOAT},
          .depth_format = VK_FORMAT_D32_SFLOAT,
          .depth_compare = VK_COMPARE_OP_LESS_OR_EQUAL,
          .depth_write = false,
          .color_write_masks = {VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                                    VK_COLOR_COMPONENT_A_BIT,
                                0},
          .constants = {{MSM_SPEC_LINEAR_RADIANCE, linear ? 1u : 0u}}};
}

// The shading's bindings but the per-draw textures (albedo, opacity): the uniforms, the shadow maps of
// the technique (a white image of the declared kind in the bindings it does not read: every
// declared binding needs a valid descriptor), the blue noise, the lights, white images in place of
// the deferred pass's surfaces and the soft techniques' clamp counts.
std::vector<vk::Descriptor> frame_descriptors(const PassContext& c, const FrameConfig& config, bool shadow_maps) {
  const GpuScene& scene = c.frame.scene;
  const Technique& t = *config.technique;
  bool depth_based = t.depth_based(), soft = t.soft(), nonlinear = t.nonlinear();
  auto array_of = [&](const std::string& name, VkSampler sampler) {
    return vk::Descriptor(c.image(name).array_view, kReadOnly, sampler);
  };
  VkSampler moment_sampler = nonlinear ? c.frame.point_sampler : c.frame.linear_sampler;
  vk::Descriptor white(scene.white.view(), kReadOnly, c.frame.point_sampler);
  vk::Descriptor white_array(scene.white_array, kReadOnly, c.frame.point_sampler);
  // Every shadow-map binding is an array (one layer per light); the unused ones get an image of the
  // declared kind. The surfaces pass reads none.
  vk::Descriptor first = !shadow_maps  ? white_array
                         : depth_based ? array_of(kShadowDepth, c.frame.point_sampler)
                         : soft        ? array_of(sat_table(0), c.frame.point_sampler)
                                       : array_of(moment_image(0, 0), moment_sampler);
  bool two = config.moment_images() > 1;
  vk::Descriptor second = depth_based || !shadow_maps ? white
                          : nonlinear                 ? white_array
                          : !two                      ? first
                          : soft                      ? array_of(sat_table(1), c.frame.point_sampler)
                                                      : array_of(moment_image(0, 1), moment_sampler);
  vk::Descriptor noise(c.frame.blue_noise.view(), kReadOnly, c.frame.point_sampler);
  std::array<vk::Descriptor, 4> colour{first, second, first, second};
  if (config.coloured && shadow_maps)
    for (int channel = 1; channel < 3; ++channel)
      for (int i = 0; i < 2; ++i)
        colour[size_t(2 * (channel - 1) + i)] =
            array_of(moment_image(channel, std::min(i, config.moment_images() - 1)), moment_sampler);
  return vk::descriptors_at({{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
                             {MSM_BINDING_SHADING_ALBEDO_TEXTURE, white},
                             {MSM_BINDING_SHADING_SHADOW_MAP, first},
                             {MSM_BINDING_SHADING_SHADOW_MAP1, second},
                             {MSM_BINDING_SHADING_BLUE_NOISE, noise},
                             {MSM_BINDING_SHADING_OPACITY_TEXTURE, white},
                             {MSM_BINDING_SHADING_GREEN_MOMENTS, colour[0]},
                             {MSM_BINDING_SHADING_GREEN_MOMENTS1, colour[1]},
                             {MSM_BINDING_SHADING_BLUE_MOMENTS, colour[2]},
                             {MSM_BINDING_SHADING_BLUE_MOMENTS1, colour[3]},
                             {MSM_BINDING_SHADING_LIGHTS, vk::Descriptor(c.frame.lights)},
                             {MSM_BINDING_SHADING_SURFACE_POSITION, white},
                             {MSM_BINDING_SHADING_SURFACE_NORMAL, white},
                             {MSM_BINDING_SHADING_SURFACE_ALBEDO, white},
                             {MSM_BINDING_SHADING_SOFT_CLAMPS, vk::Descriptor(*c.frame.soft_clamps)},
                             {MSM_BINDING_SHADING_SURFACE_GEOMETRIC_NORMAL, white}});
}

// Draws the scene's `draws` (in that order) with `program`, each with its albedo and opacity textures.
void draw_scene(const PassContext& c, const vk::Program& program, std::vector<vk::Descriptor> descriptors,
                std::span<const Draw* const> draws) {
  const GpuScene& scene = c.frame.scene;
  for (const Draw* d : draws) {
    const vk::Image& texture = d->texture >= 0 ? scene.textures[size_t(d->texture)] : scene.white;
    const vk::Image& opacity =
        d->opacity_texture >= 0 ? scene.opacity_textures[size_t(d->opacity_texture)] : scene.white;
    descriptors[MSM_BINDING_SHADING_ALBEDO_TEXTURE] = vk::Descriptor(texture.view(), kReadOnly, scene.texture_sampler);
    descriptors[MSM_BINDING_SHADING_OPACITY_TEXTURE] = vk::Descriptor(opacity.view(), kReadOnly, scene.texture_sampler);
    vkCmdSetCullMode(c.cmd, d->double_sided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT);
    vk::bind_program(c.cmd, program, descriptors, std::as_bytes(std::span(&d->push, 1)));
    vkCmdDrawIndexed(c.cmd, d->index_count, 1, d->first_index, 0, 0);
  }
}

std::vector<const Draw*> opaque_draws(const GpuScene& scene) {
  std::vector<const Draw*> draws;
  for (const Draw& d : scene.draws) draws.push_back(&d);
  return draws;
}

} // namespace

void SurfacesPass::prepare(const PassResources& r) {
  program_ = &r.programs.graphics(shading_desc(config_, Stage::surfaces));
}

void SurfacesPass::reflect(PassBuilder& b) const {
  uint32_t w = uint32_t(config_.width), h = uint32_t(config_.height);
  for (const char* name : {kSurfacePosition, kSurfaceNormal, kSurfaceAlbedo, kSurfaceGeometricNormal})
    b.create(name, {.format = VK_FORMAT_R32G32B32A32_SFLOAT, .width = w, .height = h}, use::color_attachment());
  b.create(kCameraDepth, {.format = VK_FORMAT_D32_SFLOAT, .width = w, .height = h}, use::depth_attachment());
}

void SurfacesPass::execute(const PassContext& c) const {
  VkExtent2D size{uint32_t(config_.width), uint32_t(config_.height)};
  VkClearColorValue none{{0.0f, 0.0f, 0.0f, 0.0f}}; // w = 0: no surface
  vk::begin_rendering(c.cmd, size,
                      {{c.image(kSurfacePosition).layer_views[0], none},
                       {c.image(kSurfaceNormal).layer_views[0], none},
                       {c.image(kSurfaceAlbedo).layer_views[0], none},
                       {c.image(kSurfaceGeometricNormal).layer_views[0], none}},
                      vk::DepthAttachment{c.image(kCameraDepth).layer_views[0], 1.0f});
  vk::set_viewport_scissor(c.cmd, size);
  bind_scene(c.cmd, c.frame.scene);
  draw_scene(c, *program_, frame_descriptors(c, config_, false), opaque_draws(c.frame.scene));
  vkCmdEndRendering(c.cmd);
}

void ShadingPass::prepare(const PassResources& r) {
  program_ = &r.programs.graphics(shading_desc(config_, config_.deferred ? Stage::deferred : Stage::opaque));
  translucent_program_ = &r.programs.graphics(shading_desc(config_, Stage::translucent));
  background_program_ = &r.programs.graphics(background_desc(config_));
}

void ShadingPass::reflect(PassBuilder& b) const {
  const VkPipelineStageFlags2 fragment = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
  const Technique& t = *config_.technique;
  if (t.depth_based()) {
    b.read(kShadowDepth, use::sampled(fragment));
  } else if (t.soft()) {
    for (int i = 0; i < config_.moment_images(); ++i) b.read(sat_table(i), use::sampled(fragment));
  } else {
    for (int channel = 0; channel < config_.channels(); ++channel)
      for (int i = 0; i < config_.moment_images(); ++i) b.read(moment_image(channel, i), use::sampled(fragment));
  }
  uint32_t w = uint32_t(config_.width), h = uint32_t(config_.height);
  if (t.scatters())
    b.create(kSurfaceRadiance, {.format = VK_FORMAT_R16G16B16A16_SFLOAT, .width = w, .height = h},
             use::color_attachment());
  else
    b.create(kColor, {.format = VK_FORMAT_R8G8B8A8_SRGB, .width = w, .height = h}, use::color_attachment());
  b.create(kShadowBuffer, {.format = VK_FORMAT_R32G32B32A32_SFLOAT, .width = w, .height = h}, use::color_attachment());
  if (config_.deferred) {
    for (const char* name : {kSurfacePosition, kSurfaceNormal, kSurfaceAlbedo, kSurfaceGeometricNormal})
      b.read(name, use::sampled(fragment));
    b.modify(kCameraDepth, use::depth_attachment()); // the translucent draws test against it
  } else {
    b.create(kCameraDepth, {.format = VK_FORMAT_D32_SFLOAT, .width = w, .height = h}, use::depth_attachment());
  }
}

void ShadingPass::execute(const PassContext& c) const {
  const GpuScene& scene = c.frame.scene;
  // Scattering techniques: the linear radiance (the sky's too), composited by the scattering pass.
  bool scatters = config_.technique->scatters();
  const GraphImage& color = c.image(scatters ? kSurfaceRadiance : kColor);
  const GraphImage& shadow_buffer = c.image(kShadowBuffer);
  VkExtent2D size{uint32_t(config_.width), uint32_t(config_.height)};
  // The background: visibility 1 (nothing to shadow), coverage 0. The sky colour is linear.
  glm::vec3 sky_radiance = scatters ? glm::vec3(c.frame.scattering.sky) : MSM_SKY_RADIANCE; // shown the same
  VkClearColorValue sky{{sky_radiance.r, sky_radiance.g, sky_radiance.b, 1.0f}}, lit{{1.0f, 1.0f, 1.0f, 0.0f}};
  vk::begin_rendering(c.cmd, size, {{color.layer_views[0], sky}, {shadow_buffer.layer_views[0], lit}},
                      vk::DepthAttachment{c.image(kCameraDepth).layer_views[0], 1.0f, config_.deferred});
  vk::set_viewport_scissor(c.cmd, size);
  bind_scene(c.cmd, scene);
  std::vector<vk::Descriptor> descriptors = frame_descriptors(c, config_, true);
  if (config_.deferred) { // one full-screen triangle over the surfaces
    std::vector<vk::Descriptor> deferred = descriptors;
    auto surface = [&](const char* name) {
      return vk::Descriptor(c.image(name).layer_views[0], kReadOnly, c.frame.point_sampler);
    };
    deferred[MSM_BINDING_SHADING_SURFACE_POSITION] = surface(kSurfacePosition);
    deferred[MSM_BINDING_SHADING_SURFACE_NORMAL] = surface(kSurfaceNormal);
    deferred[MSM_BINDING_SHADING_SURFACE_ALBEDO] = surface(kSurfaceAlbedo);
    deferred[MSM_BINDING_SHADING_SURFACE_GEOMETRIC_NORMAL] = surface(kSurfaceGeometricNormal);
    vkCmdSetCullMode(c.cmd, VK_CULL_MODE_NONE);
    ObjectPush none{};
    vk::bind_program(c.cmd, *program_, deferred, std::as_bytes(std::span(&none, 1)));
    vkCmdDraw(c.cmd, 3, 1, 0, 0);
  } else {
    draw_scene(c, *program_, descriptors, opaque_draws(scene));
  }
  if (scene.probe) {
    vkCmdSetCullMode(c.cmd, VK_CULL_MODE_NONE);
    vk::bind_program(
        c.cmd, *background_program_,
        {{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
         {MSM_BINDING_BACKGROUND_PROBE, vk::Descriptor(scene.probe.view(), kReadOnly, c.frame.point_sampler)}},
        std::as_bytes(std::span(&c.frame.scattering, 1)));
    vkCmdDraw(c.cmd, 3, 1, 0, 0);
  }
  // Translucent surfaces over the opaque image, far to near from the camera (per object).
  std::vector<const Draw*> order;
  for (const Draw& d : scene.translucent) order.push_back(&d);
  std::stable_sort(order.begin(), order.end(), [&](const Draw* a, const Draw* b) {
    return glm::distance(a->center, c.frame.camera_position) > glm::distance(b->center, c.frame.camera_position);
  });
  draw_scene(c, *translucent_program_, descriptors, order);
  vkCmdEndRendering(c.cmd);
}

} // namespace msm::render
