#include "msm/vk/program.h"

#include "msm/shared.h" // MSM_SPEC_FUSED_FMA_ID
#include "msm/vk/context.h"
#include "msm/vk/shaders.h"

#include <fmt/format.h>

namespace msm::vk {
namespace {

VkDescriptorType descriptorType(Binding binding) {
  switch (binding) {
  case Binding::StorageBuffer: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  case Binding::UniformBuffer: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  case Binding::StorageImage: return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  case Binding::SampledImage: return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  }
  throw std::invalid_argument("msm::vk: unknown Binding");
}

} // namespace

SharedSpecialization::SharedSpecialization(const Context& ctx, std::span<const SpecConstant> extra) {
  values_.push_back(ctx.useNativeFma() ? VK_TRUE : VK_FALSE);
  entries_.push_back({.constantID = MSM_SPEC_FUSED_FMA_ID, .offset = 0, .size = sizeof(uint32_t)});
  for (const SpecConstant& c : extra) {
    for (const VkSpecializationMapEntry& e : entries_)
      if (e.constantID == c.id)
        throw std::invalid_argument(fmt::format("msm::vk: specialization constant {} given twice", c.id));
    entries_.push_back({.constantID = c.id, .offset = uint32_t(values_.size() * sizeof(uint32_t)), .size = sizeof(uint32_t)});
    values_.push_back(c.value);
  }
  info_ = {.mapEntryCount = uint32_t(entries_.size()), .pMapEntries = entries_.data(),
           .dataSize = values_.size() * sizeof(uint32_t), .pData = values_.data()};
}

// Everything of a Program but its pipeline: descriptor set layout (push descriptors), pipeline
// layout and update template, for the given stages and bind point.
Program createProgramLayout(const Context& ctx, std::string_view name, std::span<const Binding> bindings,
                            uint32_t pushConstantSize, VkShaderStageFlags stages, VkPipelineBindPoint bindPoint) {
  if (pushConstantSize % 4 || pushConstantSize > ctx.properties().limits.maxPushConstantsSize)
    throw std::invalid_argument(fmt::format("msm::vk: program {}: push constant size {} (multiple of 4, at most {})",
                                            name, pushConstantSize, ctx.properties().limits.maxPushConstantsSize));
  VkPhysicalDevicePushDescriptorPropertiesKHR pushProps{
      .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 props{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &pushProps};
  vkGetPhysicalDeviceProperties2(ctx.physicalDevice(), &props);
  if (bindings.size() > pushProps.maxPushDescriptors)
    throw std::invalid_argument(fmt::format("msm::vk: program {}: {} bindings, the device pushes at most {}",
                                            name, bindings.size(), pushProps.maxPushDescriptors));

  VkDevice device = ctx.device();
  Program p;
  p.name_ = name;
  p.bindings_.assign(bindings.begin(), bindings.end());
  p.pushConstantSize_ = pushConstantSize;
  p.pushDescriptors_ = ctx.cmdPushDescriptorSetWithTemplate();
  p.stages_ = stages;
  p.bindPoint_ = bindPoint;

  std::vector<VkDescriptorSetLayoutBinding> layoutBindings;
  std::vector<VkDescriptorUpdateTemplateEntry> entries;
  for (uint32_t i = 0; i < bindings.size(); ++i) {
    VkDescriptorType type = descriptorType(bindings[i]);
    layoutBindings.push_back({.binding = i, .descriptorType = type, .descriptorCount = 1,
                              .stageFlags = stages});
    // dispatch() hands over Descriptor[]: entry i reads element i, whichever union member it is.
    entries.push_back({.dstBinding = i, .descriptorCount = 1, .descriptorType = type,
                       .offset = i * sizeof(Descriptor), .stride = sizeof(Descriptor)});
  }
  if (!bindings.empty()) {
    VkDescriptorSetLayoutCreateInfo info{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                         .flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR,
                                         .bindingCount = uint32_t(layoutBindings.size()),
                                         .pBindings = layoutBindings.data()};
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateDescriptorSetLayout(device, &info, nullptr, &setLayout));
    p.setLayout_ = {device, setLayout};
  }

  VkPushConstantRange range{stages, 0, pushConstantSize};
  VkDescriptorSetLayout setLayout = p.setLayout_;
  VkPipelineLayoutCreateInfo layoutInfo{.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
                                        .setLayoutCount = setLayout ? 1u : 0u,
                                        .pSetLayouts = &setLayout,
                                        .pushConstantRangeCount = pushConstantSize ? 1u : 0u,
                                        .pPushConstantRanges = &range};
  VkPipelineLayout layout = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout));
  p.layout_ = {device, layout};

  if (!bindings.empty()) {
    VkDescriptorUpdateTemplateCreateInfo info{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO,
                                              .descriptorUpdateEntryCount = uint32_t(entries.size()),
                                              .pDescriptorUpdateEntries = entries.data(),
                                              .templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR,
                                              .pipelineBindPoint = bindPoint,
                                              .pipelineLayout = layout,
                                              .set = 0};
    VkDescriptorUpdateTemplate updateTemplate = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateDescriptorUpdateTemplate(device, &info, nullptr, &updateTemplate));
    p.template_ = {device, updateTemplate};
  }

  return p;
}

Program createProgram(const Context& ctx, std::span<const uint32_t> spirv, std::string_view name,
                      std::span<const Binding> bindings, uint32_t pushConstantSize,
                      std::span<const SpecConstant> constants) {
  if (spirv.empty() || spirv[0] != 0x07230203u)
    throw std::invalid_argument(fmt::format("msm::vk::createProgram({}): not SPIR-V", name));
  Program p = createProgramLayout(ctx, name, bindings, pushConstantSize, VK_SHADER_STAGE_COMPUTE_BIT,
                                  VK_PIPELINE_BIND_POINT_COMPUTE);
  VkDevice device = ctx.device();
  VkPipelineLayout layout = p.layout_;
  VkShaderModuleCreateInfo moduleInfo{.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                      .codeSize = spirv.size_bytes(),
                                      .pCode = spirv.data()};
  VkShaderModule rawModule = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateShaderModule(device, &moduleInfo, nullptr, &rawModule));
  ShaderModule module(device, rawModule); // only needed while the pipeline is created
  SharedSpecialization specialization(ctx, constants);
  VkComputePipelineCreateInfo pipelineInfo{
      .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
      .stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                .module = module,
                .pName = "main",
                .pSpecializationInfo = specialization.info()},
      .layout = layout};
  VkPipeline pipeline = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &pipelineInfo, nullptr, &pipeline));
  p.pipeline_ = {device, pipeline};
  ctx.setObjectName(VK_OBJECT_TYPE_PIPELINE, pipeline, p.name_);
  return p;
}

Program createProgram(const Context& ctx, std::string_view shader, std::initializer_list<Binding> bindings,
                      uint32_t pushConstantSize, std::initializer_list<SpecConstant> constants) {
  return createProgram(ctx, embedded_shader(shader), shader, std::span<const Binding>(bindings.begin(), bindings.size()),
                       pushConstantSize, std::span<const SpecConstant>(constants.begin(), constants.size()));
}

void dispatch(VkCommandBuffer cmd, const Program& program, uint32_t groupsX, uint32_t groupsY, uint32_t groupsZ,
              std::span<const Descriptor> bindings, std::span<const std::byte> pushConstants) {
  if (bindings.size() != program.bindings_.size())
    throw std::invalid_argument(fmt::format("msm::vk::dispatch({}): {} descriptors given, the program has {} bindings",
                                            program.name_, bindings.size(), program.bindings_.size()));
  if (pushConstants.size() != program.pushConstantSize_)
    throw std::invalid_argument(fmt::format("msm::vk::dispatch({}): {} bytes of push constants given, the program "
                                            "takes {}", program.name_, pushConstants.size(), program.pushConstantSize_));
  if (program.bindPoint_ != VK_PIPELINE_BIND_POINT_COMPUTE)
    throw std::invalid_argument(fmt::format("msm::vk::dispatch({}): not a compute program", program.name_));
  bindProgram(cmd, program, bindings, pushConstants);
  vkCmdDispatch(cmd, groupsX, groupsY, groupsZ);
}

void bindProgram(VkCommandBuffer cmd, const Program& program, std::span<const Descriptor> bindings,
                 std::span<const std::byte> pushConstants) {
  if (bindings.size() != program.bindings_.size())
    throw std::invalid_argument(fmt::format("msm::vk::bindProgram({}): {} descriptors given, the program has {} "
                                            "bindings", program.name_, bindings.size(), program.bindings_.size()));
  if (pushConstants.size() != program.pushConstantSize_)
    throw std::invalid_argument(fmt::format("msm::vk::bindProgram({}): {} bytes of push constants given, the program "
                                            "takes {}", program.name_, pushConstants.size(), program.pushConstantSize_));
  vkCmdBindPipeline(cmd, program.bindPoint_, program.pipeline_);
  if (!bindings.empty()) program.pushDescriptors_(cmd, program.template_, program.layout_, 0, bindings.data());
  if (!pushConstants.empty())
    vkCmdPushConstants(cmd, program.layout_, program.stages_, 0, uint32_t(pushConstants.size()), pushConstants.data());
}

} // namespace msm::vk
