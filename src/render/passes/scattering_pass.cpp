#include "pass.h"

#include "msm/techniques.h"

namespace msm::render {

bool ScatteringPass::prefiltered() const { return config_.technique->prefiltered_scattering(); }
bool ScatteringPass::six_moments() const { return msm_technique_scatter_representation6(config_.technique->id) >= 0; }

void ScatteringPass::prepare(const PassResources& r) {
  vk::GraphicsDesc d{.name = std::string("scattering ") + std::string(config_.technique->name),
                     .vertex_shader = "fullscreen.vert",
                     .fragment_shader = six_moments() ? "scatter_prefiltered6.frag"
                                        : config_.technique->scattering == Scattering::prefiltered_csm
                                            ? "scatter_prefiltered_csm.frag"
                                        : prefiltered()     ? "scatter_prefiltered.frag"
                                        : config_.msaa == 1 ? "scatter_march_1x.frag"
                                                            : "scatter_march.frag",
                     .bindings = vk::bindings_at({{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                                  {MSM_BINDING_SCATTER_SURFACE_RADIANCE, vk::Binding::sampled_image},
                                                  {MSM_BINDING_SCATTER_CAMERA_DEPTH, vk::Binding::sampled_image},
                                                  {MSM_BINDING_SCATTER_SHADOW_MAP, vk::Binding::sampled_image},
                                                  {MSM_BINDING_SCATTER_BLUE_NOISE, vk::Binding::sampled_image},
                                                  {MSM_BINDING_SCATTER_LIGHTS, vk::Binding::storage_buffer},
                                                  {MSM_BINDING_SCATTER_RECTS, vk::Binding::storage_buffer},
                                                  {MSM_BINDING_SCATTER_PREFIX_SUMS1, vk::Binding::sampled_image}}),
                     .push_constant_size = sizeof(ScatteringPush),
                     .color_formats = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R32G32B32A32_SFLOAT},
                     .depth_write = false,
                     // One light: the loop over the lights and its layer folded to 0 (scatter.glsl).
                     .constants = {{MSM_SPEC_LIGHT_COUNT, uint32_t(config_.lights)},
                                   // The transmittance layers per light (scatter.glsl; 1: the paper's Δ(v)).
                                   {MSM_SPEC_SCATTER_LAYERS, uint32_t(config_.transmittance_layers)},
                                   // App. D.5's mips of the prefix sums: the level per pixel only with them.
                                   {MSM_SPEC_PREFIX_SUM_MIPS, config_.prefix_sum_mips > 1 ? 1u : 0u},
                                   // β: proportional, fixed or §5.3.1's adaptive (scattering.h).
                                   {MSM_SPEC_SCATTER_BETA_MODE, uint32_t(config_.scattering_beta)},
                                   // Spot lights' in-scattering along the ray (ray marching and prefiltered).
                                   {MSM_SPEC_SPOT_LIGHTS, config_.spot_lights > 0 ? 1u : 0u}}};
  program_ = &r.programs.graphics(d);
}

void ScatteringPass::reflect(PassBuilder& b) const {
  const VkPipelineStageFlags2 fragment = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
  b.read(kCameraDepth, use::sampled(fragment));
  b.read(kSurfaceRadiance, use::sampled(fragment));
  // Ray marching reads the depth map, the prefiltered techniques their prefix sums (every light's layer).
  b.read(prefiltered() ? kPrefixSums : kShadowDepth, use::sampled(fragment));
  if (six_moments()) b.read(kPrefixSums1, use::sampled(fragment));
  uint32_t w = uint32_t(config_.width), h = uint32_t(config_.height);
  b.create(kColor, {.format = VK_FORMAT_R8G8B8A8_SRGB, .width = w, .height = h}, use::color_attachment());
  b.create(kScattering, {.format = VK_FORMAT_R32G32B32A32_SFLOAT, .width = w, .height = h}, use::color_attachment());
}

void ScatteringPass::execute(const PassContext& c) const {
  VkExtent2D size{uint32_t(config_.width), uint32_t(config_.height)};
  vk::begin_rendering(c.cmd, size, {{c.image(kColor).layer_views[0], {}}, {c.image(kScattering).layer_views[0], {}}});
  vk::set_viewport_scissor(c.cmd, size);
  vkCmdSetCullMode(c.cmd, VK_CULL_MODE_NONE);
  const VkImageLayout read_only = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  VkSampler point = c.frame.point_sampler;
  vk::bind_program(
      c.cmd, *program_,
      {{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
       {MSM_BINDING_SCATTER_SURFACE_RADIANCE,
        vk::Descriptor(c.image(kSurfaceRadiance).layer_views[0], read_only, point)},
       {MSM_BINDING_SCATTER_CAMERA_DEPTH, vk::Descriptor(c.image(kCameraDepth).layer_views[0], read_only, point)},
       // Every light's layers as one array (CSM: eight per light).
       {MSM_BINDING_SCATTER_SHADOW_MAP,
        prefiltered() ? vk::Descriptor(c.image(kPrefixSums).array_view, read_only, *c.frame.repeat_sampler)
                      : vk::Descriptor(c.image(kShadowDepth).array_view, read_only, point)},
       {MSM_BINDING_SCATTER_BLUE_NOISE, vk::Descriptor(c.frame.blue_noise.view(), read_only, point)},
       {MSM_BINDING_SCATTER_LIGHTS, vk::Descriptor(c.frame.lights)},
       {MSM_BINDING_SCATTER_RECTS, vk::Descriptor(*c.frame.rectification)},
       // The second image of six moments (the others: any 2D image, unused).
       {MSM_BINDING_SCATTER_PREFIX_SUMS1,
        six_moments() ? vk::Descriptor(c.image(kPrefixSums1).array_view, read_only, *c.frame.repeat_sampler)
                      : vk::Descriptor(c.image(kSurfaceRadiance).layer_views[0], read_only, *c.frame.repeat_sampler)}},
      c.frame.scattering);
  vkCmdDraw(c.cmd, 3, 1, 0, 0);
  vkCmdEndRendering(c.cmd);
}

} // namespace msm::render
