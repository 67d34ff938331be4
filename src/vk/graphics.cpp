#include "msm/vk/graphics.h"

#include "msm/vk/context.h"
#include "msm/vk/shaders.h"

#include <fmt/format.h>

namespace msm::vk {

bool supportsAttachment(const Context& ctx, VkFormat format, VkSampleCountFlagBits samples) {
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), format, &props);
  bool depth = formatAspect(format) & VK_IMAGE_ASPECT_DEPTH_BIT;
  VkFormatFeatureFlags need = depth ? VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
  if ((props.optimalTilingFeatures & need) != need) return false;
  VkImageFormatProperties image{};
  VkResult r = vkGetPhysicalDeviceImageFormatProperties(
      ctx.physicalDevice(), format, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL,
      depth ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, 0, &image);
  return r == VK_SUCCESS && (image.sampleCounts & samples);
}

Program createGraphicsProgram(const Context& ctx, const GraphicsDesc& desc) {
  if (desc.vertexShader.empty())
    throw std::invalid_argument(fmt::format("msm::vk::createGraphicsProgram({}): no vertex shader", desc.name));
  if (desc.colorFormats.empty() && desc.depthFormat == VK_FORMAT_UNDEFINED)
    throw std::invalid_argument(fmt::format("msm::vk::createGraphicsProgram({}): no attachment", desc.name));
  for (VkFormat f : desc.colorFormats)
    if (!supportsAttachment(ctx, f, desc.samples))
      throw std::invalid_argument(fmt::format("msm::vk::createGraphicsProgram({}): color format {} with {} samples is "
                                              "not supported by {}", desc.name, int(f), int(desc.samples), ctx.info().name));
  if (desc.depthFormat != VK_FORMAT_UNDEFINED && !supportsAttachment(ctx, desc.depthFormat, desc.samples))
    throw std::invalid_argument(fmt::format("msm::vk::createGraphicsProgram({}): depth format {} with {} samples is "
                                            "not supported by {}", desc.name, int(desc.depthFormat), int(desc.samples),
                                            ctx.info().name));

  VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  Program p = createProgramLayout(ctx, desc.name, desc.bindings, desc.pushConstantSize, stages,
                                  VK_PIPELINE_BIND_POINT_GRAPHICS);
  VkDevice device = ctx.device();

  auto makeModule = [&](const std::string& name) {
    std::span<const uint32_t> spirv = embedded_shader(name);
    VkShaderModuleCreateInfo info{.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                  .codeSize = spirv.size_bytes(), .pCode = spirv.data()};
    VkShaderModule module = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
    return ShaderModule(device, module);
  };
  SharedSpecialization specialization(ctx, desc.constants);
  std::vector<ShaderModule> modules;
  std::vector<VkPipelineShaderStageCreateInfo> stageInfos;
  modules.push_back(makeModule(desc.vertexShader));
  stageInfos.push_back({.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_VERTEX_BIT,
                        .module = modules.back(), .pName = "main", .pSpecializationInfo = specialization.info()});
  if (!desc.fragmentShader.empty()) {
    modules.push_back(makeModule(desc.fragmentShader));
    stageInfos.push_back({.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                          .stage = VK_SHADER_STAGE_FRAGMENT_BIT, .module = modules.back(), .pName = "main",
                          .pSpecializationInfo = specialization.info()});
  }

  VkVertexInputBindingDescription vertexBinding{.binding = 0, .stride = desc.vertexStride,
                                                .inputRate = VK_VERTEX_INPUT_RATE_VERTEX};
  std::vector<VkVertexInputAttributeDescription> attributes;
  for (const VertexAttribute& a : desc.attributes)
    attributes.push_back({.location = a.location, .binding = 0, .format = a.format, .offset = a.offset});
  VkPipelineVertexInputStateCreateInfo vertexInput{
      .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
      .vertexBindingDescriptionCount = desc.vertexStride ? 1u : 0u,
      .pVertexBindingDescriptions = &vertexBinding,
      .vertexAttributeDescriptionCount = uint32_t(attributes.size()),
      .pVertexAttributeDescriptions = attributes.data()};
  VkPipelineInputAssemblyStateCreateInfo inputAssembly{.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
                                                       .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST};
  VkPipelineViewportStateCreateInfo viewport{.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
                                             .viewportCount = 1, .scissorCount = 1};
  VkPipelineRasterizationStateCreateInfo raster{
      .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
      .depthClampEnable = desc.depthClamp && ctx.features().core.depthClamp ? VK_TRUE : VK_FALSE,
      .polygonMode = VK_POLYGON_MODE_FILL,
      .cullMode = VK_CULL_MODE_NONE,
      .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
      .depthBiasEnable = desc.depthBias ? VK_TRUE : VK_FALSE,
      .lineWidth = 1.0f};
  VkPipelineMultisampleStateCreateInfo multisample{.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
                                                   .rasterizationSamples = desc.samples};
  bool hasDepth = desc.depthFormat != VK_FORMAT_UNDEFINED;
  VkPipelineDepthStencilStateCreateInfo depthStencil{
      .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
      .depthTestEnable = hasDepth ? VK_TRUE : VK_FALSE,
      .depthWriteEnable = hasDepth && desc.depthWrite ? VK_TRUE : VK_FALSE,
      .depthCompareOp = desc.depthCompare,
      .minDepthBounds = 0.0f,
      .maxDepthBounds = 1.0f};
  constexpr VkColorComponentFlags rgba = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                        VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  if (!desc.colorWriteMasks.empty() && desc.colorWriteMasks.size() != desc.colorFormats.size())
    throw std::invalid_argument(fmt::format("msm::vk::createGraphicsProgram({}): one write mask per colour attachment",
                                            desc.name));
  std::vector<VkPipelineColorBlendAttachmentState> blend;
  for (size_t i = 0; i < desc.colorFormats.size(); ++i) {
    if (desc.alphaBlend) {
      VkFormatProperties props{};
      vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), desc.colorFormats[i], &props);
      if (!(props.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT))
        throw std::invalid_argument(fmt::format("msm::vk::createGraphicsProgram({}): {} cannot blend format {}",
                                                desc.name, ctx.info().name, int(desc.colorFormats[i])));
    }
    blend.push_back({.blendEnable = desc.alphaBlend ? VK_TRUE : VK_FALSE,
                     .srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA,
                     .dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
                     .colorBlendOp = VK_BLEND_OP_ADD,
                     .srcAlphaBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA,
                     .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
                     .alphaBlendOp = VK_BLEND_OP_ADD,
                     .colorWriteMask = desc.colorWriteMasks.empty() ? rgba : desc.colorWriteMasks[i]});
  }
  VkPipelineColorBlendStateCreateInfo colorBlend{.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
                                                 .attachmentCount = uint32_t(blend.size()),
                                                 .pAttachments = blend.data()};
  std::vector<VkDynamicState> dynamic = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR, VK_DYNAMIC_STATE_CULL_MODE};
  if (desc.depthBias) dynamic.push_back(VK_DYNAMIC_STATE_DEPTH_BIAS);
  VkPipelineDynamicStateCreateInfo dynamicState{.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
                                                .dynamicStateCount = uint32_t(dynamic.size()),
                                                .pDynamicStates = dynamic.data()};
  VkPipelineRenderingCreateInfo rendering{.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
                                          .colorAttachmentCount = uint32_t(desc.colorFormats.size()),
                                          .pColorAttachmentFormats = desc.colorFormats.data(),
                                          .depthAttachmentFormat = desc.depthFormat};
  VkGraphicsPipelineCreateInfo info{.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
                                    .pNext = &rendering,
                                    .stageCount = uint32_t(stageInfos.size()),
                                    .pStages = stageInfos.data(),
                                    .pVertexInputState = &vertexInput,
                                    .pInputAssemblyState = &inputAssembly,
                                    .pViewportState = &viewport,
                                    .pRasterizationState = &raster,
                                    .pMultisampleState = &multisample,
                                    .pDepthStencilState = &depthStencil,
                                    .pColorBlendState = &colorBlend,
                                    .pDynamicState = &dynamicState,
                                    .layout = p.layout_};
  VkPipeline pipeline = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
  p.pipeline_ = {device, pipeline};
  ctx.setObjectName(VK_OBJECT_TYPE_PIPELINE, pipeline, p.name_);
  return p;
}

void beginRendering(VkCommandBuffer cmd, VkExtent2D extent, std::span<const ColorAttachment> colors,
                    std::optional<DepthAttachment> depth) {
  std::vector<VkRenderingAttachmentInfo> colorInfos;
  for (const ColorAttachment& c : colors)
    colorInfos.push_back({.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                          .imageView = c.view,
                          .imageLayout = c.layout,
                          .resolveMode = c.resolve ? VK_RESOLVE_MODE_AVERAGE_BIT : VK_RESOLVE_MODE_NONE,
                          .resolveImageView = c.resolve,
                          .resolveImageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                          .loadOp = c.load ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR,
                          .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                          .clearValue = {.color = c.clear}});
  VkRenderingAttachmentInfo depthInfo{};
  if (depth)
    depthInfo = {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
                 .imageView = depth->view,
                 .imageLayout = depth->layout,
                 .loadOp = depth->load ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR,
                 .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
                 .clearValue = {.depthStencil = {depth->clear, 0}}};
  VkRenderingInfo info{.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                       .renderArea = {{0, 0}, extent},
                       .layerCount = 1,
                       .colorAttachmentCount = uint32_t(colorInfos.size()),
                       .pColorAttachments = colorInfos.data(),
                       .pDepthAttachment = depth ? &depthInfo : nullptr};
  vkCmdBeginRendering(cmd, &info);
}

void setViewportScissor(VkCommandBuffer cmd, VkExtent2D extent) {
  VkViewport viewport{0.0f, 0.0f, float(extent.width), float(extent.height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, extent};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

} // namespace msm::vk
