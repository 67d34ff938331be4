#include "msm/vk/program.h"

#include "msm/shared.h" // MSM_SPEC_FUSED_FMA_ID
#include "msm/vk/context.h"
#include "msm/vk/shaders.h"

#include <fmt/format.h>

namespace msm::vk {
namespace {

VkDescriptorType descriptor_type(Binding binding) {
  switch (binding) {
  case Binding::storage_buffer: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  case Binding::uniform_buffer: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  case Binding::storage_image: return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  case Binding::sampled_image: return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  }
  throw std::invalid_argument("msm::vk: unknown Binding");
}

// The length of the positional list of `given`; std::invalid_argument unless the numbers are
// 0 to given.size() - 1, each once.
template <class At>
std::size_t positional_count(std::span<const At> given, const char* what) {
  std::vector<bool> seen(given.size(), false);
  for (const At& at : given) {
    if (at.binding >= given.size())
      throw std::invalid_argument(fmt::format("msm::vk::{}: binding {} among {} bindings (numbers 0 to {} each once)",
                                              what, at.binding, given.size(), given.size() - 1));
    if (seen[at.binding])
      throw std::invalid_argument(fmt::format("msm::vk::{}: binding {} given twice", what, at.binding));
    seen[at.binding] = true;
  }
  return given.size();
}

} // namespace

std::vector<Binding> bindings_at(std::span<const BindingAt> bindings) {
  std::vector<Binding> list(positional_count(bindings, "bindings_at"));
  for (const BindingAt& b : bindings) list[b.binding] = b.type;
  return list;
}

std::vector<Descriptor> descriptors_at(std::span<const DescriptorAt> descriptors) {
  std::vector<Descriptor> list(positional_count(descriptors, "descriptors_at"), Descriptor(VkBuffer(VK_NULL_HANDLE)));
  for (const DescriptorAt& d : descriptors) list[d.binding] = d.descriptor;
  return list;
}

SharedSpecialization::SharedSpecialization(const Context& ctx, std::span<const SpecConstant> extra) {
  values_.push_back(ctx.use_native_fma() ? VK_TRUE : VK_FALSE);
  entries_.push_back({.constantID = MSM_SPEC_FUSED_FMA_ID, .offset = 0, .size = sizeof(uint32_t)});
  for (const SpecConstant& c : extra) {
    for (const VkSpecializationMapEntry& e : entries_)
      if (e.constantID == c.id)
        throw std::invalid_argument(fmt::format("msm::vk: specialization constant {} given twice", c.id));
    entries_.push_back(
        {.constantID = c.id, .offset = uint32_t(values_.size() * sizeof(uint32_t)), .size = sizeof(uint32_t)});
    values_.push_back(c.value);
  }
  info_ = {.mapEntryCount = uint32_t(entries_.size()),
           .pMapEntries = entries_.data(),
           .dataSize = values_.size() * sizeof(uint32_t),
           .pData = values_.data()};
}

// Everything of a Program but its pipeline: descriptor set layout (push descriptors), pipeline
// layout and update template, for the given stages and bind point.
Program create_program_layout(const Context& ctx, std::string_view name, std::span<const Binding> bindings,
                              uint32_t push_constant_size, VkShaderStageFlags stages, VkPipelineBindPoint bind_point) {
  if (push_constant_size % 4 || push_constant_size > ctx.properties().limits.maxPushConstantsSize)
    throw std::invalid_argument(fmt::format("msm::vk: program {}: push constant size {} (multiple of 4, at most {})",
                                            name, push_constant_size, ctx.properties().limits.maxPushConstantsSize));
  VkPhysicalDevicePushDescriptorPropertiesKHR push_props{
      .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 props{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &push_props};
  vkGetPhysicalDeviceProperties2(ctx.physical_device(), &props);
  if (bindings.size() > push_props.maxPushDescriptors)
    throw std::invalid_argument(fmt::format("msm::vk: program {}: {} bindings, the device pushes at most {}", name,
                                            bindings.size(), push_props.maxPushDescriptors));

  VkDevice device = ctx.device();
  Program p;
  p.name_ = name;
  p.bindings_.assign(bindings.begin(), bindings.end());
  p.push_constant_size_ = push_constant_size;
  p.push_descriptors_ = ctx.cmd_push_descriptor_set_with_template();
  p.stages_ = stages;
  p.bind_point_ = bind_point;

  std::vector<VkDescriptorSetLayoutBinding> layout_bindings;
  std::vector<VkDescriptorUpdateTemplateEntry> entries;
  for (uint32_t i = 0; i < bindings.size(); ++i) {
    VkDescriptorType type = descriptor_type(bindings[i]);
    layout_bindings.push_back({.binding = i, .descriptorType = type, .descriptorCount = 1, .stageFlags = stages});
    // dispatch() hands over Descriptor[]: entry i reads element i, whichever union member it is.
    entries.push_back({.dstBinding = i,
                       .descriptorCount = 1,
                       .descriptorType = type,
                       .offset = i * sizeof(Descriptor),
                       .stride = sizeof(Descriptor)});
  }
  if (!bindings.empty()) {
    VkDescriptorSetLayoutCreateInfo info{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
                                         .flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR,
                                         .bindingCount = uint32_t(layout_bindings.size()),
                                         .pBindings = layout_bindings.data()};
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateDescriptorSetLayout(device, &info, nullptr, &set_layout));
    p.set_layout_ = {device, set_layout};
  }

  VkPushConstantRange range{stages, 0, push_constant_size};
  VkDescriptorSetLayout set_layout = p.set_layout_;
  VkPipelineLayoutCreateInfo layout_info{.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
                                         .setLayoutCount = set_layout ? 1u : 0u,
                                         .pSetLayouts = &set_layout,
                                         .pushConstantRangeCount = push_constant_size ? 1u : 0u,
                                         .pPushConstantRanges = &range};
  VkPipelineLayout layout = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &layout));
  p.layout_ = {device, layout};

  if (!bindings.empty()) {
    VkDescriptorUpdateTemplateCreateInfo info{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO,
                                              .descriptorUpdateEntryCount = uint32_t(entries.size()),
                                              .pDescriptorUpdateEntries = entries.data(),
                                              .templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR,
                                              .pipelineBindPoint = bind_point,
                                              .pipelineLayout = layout,
                                              .set = 0};
    VkDescriptorUpdateTemplate update_template = VK_NULL_HANDLE;
    MSM_VK_CHECK(vkCreateDescriptorUpdateTemplate(device, &info, nullptr, &update_template));
    p.template_ = {device, update_template};
  }

  return p;
}

Program create_program(const Context& ctx, std::span<const uint32_t> spirv, std::string_view name,
                       std::span<const Binding> bindings, uint32_t push_constant_size,
                       std::span<const SpecConstant> constants) {
  if (spirv.empty() || spirv[0] != 0x07230203u)
    throw std::invalid_argument(fmt::format("msm::vk::create_program({}): not SPIR-V", name));
  Program p = create_program_layout(ctx, name, bindings, push_constant_size, VK_SHADER_STAGE_COMPUTE_BIT,
                                    VK_PIPELINE_BIND_POINT_COMPUTE);
  VkDevice device = ctx.device();
  VkPipelineLayout layout = p.layout_;
  VkShaderModuleCreateInfo module_info{
      .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, .codeSize = spirv.size_bytes(), .pCode = spirv.data()};
  VkShaderModule raw_module = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateShaderModule(device, &module_info, nullptr, &raw_module));
  ShaderModule module(device, raw_module); // only needed while the pipeline is created
  SharedSpecialization specialization(ctx, constants);
  VkComputePipelineCreateInfo pipeline_info{.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
                                            .stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                                                      .stage = VK_SHADER_STAGE_COMPUTE_BIT,
                                                      .module = module,
                                                      .pName = "main",
                                                      .pSpecializationInfo = specialization.info()},
                                            .layout = layout};
  VkPipeline pipeline = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &pipeline));
  p.pipeline_ = {device, pipeline};
  ctx.set_object_name(VK_OBJECT_TYPE_PIPELINE, pipeline, p.name_);
  return p;
}

Program create_program(const Context& ctx, std::string_view shader, std::initializer_list<BindingAt> bindings,
                       uint32_t push_constant_size, std::initializer_list<SpecConstant> constants) {
  return create_program(ctx, embedded_shader(shader), shader, bindings_at(bindings), push_constant_size,
                        std::span<const SpecConstant>(constants.begin(), constants.size()));
}

void dispatch(VkCommandBuffer cmd, const Program& program, uint32_t groups_x, uint32_t groups_y, uint32_t groups_z,
              std::span<const Descriptor> bindings, std::span<const std::byte> push_constants) {
  if (bindings.size() != program.bindings_.size())
    throw std::invalid_argument(fmt::format("msm::vk::dispatch({}): {} descriptors given, the program has {} bindings",
                                            program.name_, bindings.size(), program.bindings_.size()));
  if (push_constants.size() != program.push_constant_size_)
    throw std::invalid_argument(fmt::format("msm::vk::dispatch({}): {} bytes of push constants given, the program "
                                            "takes {}",
                                            program.name_, push_constants.size(), program.push_constant_size_));
  if (program.bind_point_ != VK_PIPELINE_BIND_POINT_COMPUTE)
    throw std::invalid_argument(fmt::format("msm::vk::dispatch({}): not a compute program", program.name_));
  bind_program(cmd, program, bindings, push_constants);
  vkCmdDispatch(cmd, groups_x, groups_y, groups_z);
}

void bind_program(VkCommandBuffer cmd, const Program& program, std::span<const Descriptor> bindings,
                  std::span<const std::byte> push_constants) {
  if (bindings.size() != program.bindings_.size())
    throw std::invalid_argument(fmt::format("msm::vk::bind_program({}): {} descriptors given, the program has {} "
                                            "bindings",
                                            program.name_, bindings.size(), program.bindings_.size()));
  if (push_constants.size() != program.push_constant_size_)
    throw std::invalid_argument(fmt::format("msm::vk::bind_program({}): {} bytes of push constants given, the program "
                                            "takes {}",
                                            program.name_, push_constants.size(), program.push_constant_size_));
  vkCmdBindPipeline(cmd, program.bind_point_, program.pipeline_);
  if (!bindings.empty()) program.push_descriptors_(cmd, program.template_, program.layout_, 0, bindings.data());
  if (!push_constants.empty())
    vkCmdPushConstants(cmd, program.layout_, program.stages_, 0, uint32_t(push_constants.size()),
                       push_constants.data());
}

} // namespace msm::vk
