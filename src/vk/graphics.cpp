#include "msm/vk/graphics.h"

#include "msm/vk/context.h"
#include "msm/vk/shaders.h"

#include <fmt/format.h>

namespace msm::vk {

bool supports_attachment(const Context& ctx, VkFormat format, VkSampleCountFlagBits samples) {
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), format, &props);
  bool depth = format_aspect(format) & VK_IMAGE_ASPECT_DEPTH_BIT;
  VkFormatFeatureFlags need =
      depth ? VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
  if ((props.optimalTilingFeatures & need) != need) return false;
  VkImageFormatProperties image{};
  VkResult r = vkGetPhysicalDeviceImageFormatProperties(
      ctx.physical_device(), format, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL,
      depth ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, 0, &image);
  return r == VK_SUCCESS && (image.sampleCounts & samples);
}

namespace {

// The preconditions of create_graphics_program (std::invalid_argument naming the program).
void check_graphics_desc(const Context& ctx, const GraphicsDesc& desc) {
  if (desc.vertex_shader.empty())
    throw std::invalid_argument(fmt::format("msm::vk::create_graphics_program({}): no vertex shader", desc.name));
  if (desc.color_formats.empty() && desc.depth_format == VK_FORMAT_UNDEFINED)
    throw std::invalid_argument(fmt::format("msm::vk::create_graphics_program({}): no attachment", desc.name));
  for (VkFormat f : desc.color_formats)
    if (!supports_attachment(ctx, f, desc.samples))
      throw std::invalid_argument(
          fmt::format("msm::vk::create_graphics_program({}): color format {} with {} samples is "
                      "not supported by {}",
                      desc.name, int(f), int(desc.samples), ctx.info().name));
  if (desc.depth_format != VK_FORMAT_UNDEFINED && !supports_attachment(ctx, desc.depth_format, desc.samples))
    throw std::invalid_argument(fmt::format("msm::vk::create_graphics_program({}): depth format {} with {} samples is "
                                            "not supported by {}",
                                            desc.name, int(desc.depth_format), int(desc.samples), ctx.info().name));
  if (!desc.color_write_masks.empty() && desc.color_write_masks.size() != desc.color_formats.size())
    throw std::invalid_argument(
        fmt::format("msm::vk::create_graphics_program({}): one write mask per colour attachment", desc.name));
  for (VkFormat f : desc.color_formats) {
    if (!desc.alpha_blend) break;
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), f, &props);
    if (!(props.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT))
      throw std::invalid_argument(fmt::format("msm::vk::create_graphics_program({}): {} cannot blend format {}",
                                              desc.name, ctx.info().name, int(f)));
  }
}

// The vertex and (if any) fragment stage, each specialized with `specialization`; the modules live
// as long as this object, which must outlive the pipeline's creation.
struct ShaderStages {
  std::vector<ShaderModule> modules;
  std::vector<VkPipelineShaderStageCreateInfo> infos;

  ShaderStages(VkDevice device, const GraphicsDesc& desc, const SharedSpecialization& specialization) {
    add(device, VK_SHADER_STAGE_VERTEX_BIT, desc.vertex_shader, specialization);
    if (!desc.fragment_shader.empty()) add(device, VK_SHADER_STAGE_FRAGMENT_BIT, desc.fragment_shader, specialization);
  }

 private:
  void add(VkDevice device, VkShaderStageFlagBits stage, const std::string& shader,
           const SharedSpecialization& specialization) {
    std::span<const uint32_t> spirv = embedded_shader(shader);
    VkShaderModuleCreateInfo info{
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, .codeSize = spirv.size_bytes(), .pCode = spirv.data()};
    VkShaderModule module = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
    modules.emplace_back(device, module);
    infos.push_back({.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                     .stage = stage,
                     .module = modules.back(),
                     .pName = "main",
                     .pSpecializationInfo = specialization.info()});
  }
};

// The fixed-function state of a GraphicsDesc (the class comment of create_graphics_program in
// graphics.h). Its create infos point into the object itself: not copyable.
struct FixedFunctionState {
  VkVertexInputBindingDescription vertex_binding{};
  std::vector<VkVertexInputAttributeDescription> attributes;
  std::vector<VkPipelineColorBlendAttachmentState> blend;
  std::vector<VkDynamicState> dynamic = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR,
                                         VK_DYNAMIC_STATE_CULL_MODE};
  VkPipelineVertexInputStateCreateInfo vertex_input{};
  VkPipelineInputAssemblyStateCreateInfo input_assembly{};
  VkPipelineViewportStateCreateInfo viewport{};
  VkPipelineRasterizationStateCreateInfo raster{};
  VkPipelineMultisampleStateCreateInfo multisample{};
  VkPipelineDepthStencilStateCreateInfo depth_stencil{};
  VkPipelineColorBlendStateCreateInfo color_blend{};
  VkPipelineDynamicStateCreateInfo dynamic_state{};
  VkPipelineRenderingCreateInfo rendering{};

  FixedFunctionState(const Context& ctx, const GraphicsDesc& desc) {
    vertex_binding = {.binding = 0, .stride = desc.vertex_stride, .inputRate = VK_VERTEX_INPUT_RATE_VERTEX};
    attributes.reserve(desc.attributes.size());
    for (const VertexAttribute& a : desc.attributes)
      attributes.push_back({.location = a.location, .binding = 0, .format = a.format, .offset = a.offset});
    vertex_input = {.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
                    .vertexBindingDescriptionCount = desc.vertex_stride ? 1u : 0u,
                    .pVertexBindingDescriptions = &vertex_binding,
                    .vertexAttributeDescriptionCount = uint32_t(attributes.size()),
                    .pVertexAttributeDescriptions = attributes.data()};
    input_assembly = {.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
                      .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST};
    viewport = {.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO, .viewportCount = 1, .scissorCount = 1};
    raster = {.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
              .depthClampEnable = desc.depth_clamp && ctx.features().core.depthClamp ? VK_TRUE : VK_FALSE,
              .polygonMode = VK_POLYGON_MODE_FILL,
              .cullMode = VK_CULL_MODE_NONE,
              .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
              .depthBiasEnable = desc.depth_bias ? VK_TRUE : VK_FALSE,
              .lineWidth = 1.0f};
    multisample = {.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
                   .rasterizationSamples = desc.samples};
    bool has_depth = desc.depth_format != VK_FORMAT_UNDEFINED;
    depth_stencil = {.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
                     .depthTestEnable = has_depth ? VK_TRUE : VK_FALSE,
                     .depthWriteEnable = has_depth && desc.depth_write ? VK_TRUE : VK_FALSE,
                     .depthCompareOp = desc.depth_compare,
                     .minDepthBounds = 0.0f,
                     .maxDepthBounds = 1.0f};
    constexpr VkColorComponentFlags rgba =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    for (size_t i = 0; i < desc.color_formats.size(); ++i)
      blend.push_back({.blendEnable = desc.alpha_blend ? VK_TRUE : VK_FALSE,
                       .srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA,
                       .dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
                       .colorBlendOp = VK_BLEND_OP_ADD,
                       .srcAlphaBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA,
                       .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
                       .alphaBlendOp = VK_BLEND_OP_ADD,
                       .colorWriteMask = desc.color_write_masks.empty() ? rgba : desc.color_write_masks[i]});
    color_blend = {.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
                   .attachmentCount = uint32_t(blend.size()),
                   .pAttachments = blend.data()};
    if (desc.depth_bias) dynamic.push_back(VK_DYNAMIC_STATE_DEPTH_BIAS);
    dynamic_state = {.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
                     .dynamicStateCount = uint32_t(dynamic.size()),
                     .pDynamicStates = dynamic.data()};
    rendering = {.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
                 .colorAttachmentCount = uint32_t(desc.color_formats.size()),
                 .pColorAttachmentFormats = desc.color_formats.data(),
                 .depthAttachmentFormat = desc.depth_format};
  }
  FixedFunctionState(const FixedFunctionState&) = delete;
  FixedFunctionState& operator=(const FixedFunctionState&) = delete;
};

} // namespace

Program create_graphics_program(const Context& ctx, const GraphicsDesc& desc) {
  check_graphics_desc(ctx, desc);
  VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  Program p = create_program_layout(ctx, desc.name, desc.bindings, desc.push_constant_size, stages,
                                    VK_PIPELINE_BIND_POINT_GRAPHICS);
  VkDevice device = ctx.device();
  SharedSpecialization specialization(ctx, desc.constants);
  const ShaderStages shaders(device, desc, specialization);
  const FixedFunctionState state(ctx, desc);
  VkGraphicsPipelineCreateInfo info{.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
                                    .pNext = &state.rendering,
                                    .stageCount = uint32_t(shaders.infos.size()),
                                    .pStages = shaders.infos.data(),
                                    .pVertexInputState = &state.vertex_input,
                                    .pInputAssemblyState = &state.input_assembly,
                                    .pViewportState = &state.viewport,
                                    .pRasterizationState = &state.raster,
                                    .pMultisampleState = &state.multisample,
                                    .pDepthStencilState = &state.depth_stencil,
                                    .pColorBlendState = &state.color_blend,
                                    .pDynamicState = &state.dynamic_state,
                                    .layout = p.layout_};
  VkPipeline pipeline = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
  p.pipeline_ = {device, pipeline};
  ctx.set_object_name(VK_OBJECT_TYPE_PIPELINE, pipeline, p.name_);
  return p;
}

void begin_rendering(VkCommandBuffer cmd, VkExtent2D extent, std::span<const ColorAttachment> colors,
                     std::optional<DepthAttachment> depth) {
  std::vector<VkRenderingAttachmentInfo> color_infos;
  for (const ColorAttachment& c : colors)
    color_infos.push_back({.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                           .imageView = c.view,
                           .imageLayout = c.layout,
                           .resolveMode = c.resolve ? VK_RESOLVE_MODE_AVERAGE_BIT : VK_RESOLVE_MODE_NONE,
                           .resolveImageView = c.resolve,
                           .resolveImageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                           .loadOp = c.load ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR,
                           .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                           .clearValue = {.color = c.clear}});
  VkRenderingAttachmentInfo depth_info{};
  if (depth)
    depth_info = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                  .imageView = depth->view,
                  .imageLayout = depth->layout,
                  .loadOp = depth->load ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR,
                  .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                  .clearValue = {.depthStencil = {depth->clear, 0}}};
  VkRenderingInfo info{.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                       .renderArea = {{0, 0}, extent},
                       .layerCount = 1,
                       .colorAttachmentCount = uint32_t(color_infos.size()),
                       .pColorAttachments = color_infos.data(),
                       .pDepthAttachment = depth ? &depth_info : nullptr};
  vkCmdBeginRendering(cmd, &info);
}

void set_viewport_scissor(VkCommandBuffer cmd, VkExtent2D extent) {
  VkViewport viewport{0.0f, 0.0f, float(extent.width), float(extent.height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, extent};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

} // namespace msm::vk
