// Compute programs: a pipeline from embedded SPIR-V whose descriptors are pushed
// (VK_KHR_push_descriptor, through a descriptor update template), and a one-call dispatch.
//
//   Program p = create_program(ctx, "selftest", {{MSM_BINDING_SELFTEST_SOURCE, Binding::storage_buffer},
//                                                {MSM_BINDING_SELFTEST_DESTINATION, Binding::storage_buffer}}, sizeof(Push));
//   dispatch(cmd, p, group_count(n, 64), 1, 1,
//            {{MSM_BINDING_SELFTEST_SOURCE, input}, {MSM_BINDING_SELFTEST_DESTINATION, output}}, Push{n});
//
// Binding numbers are named once, in a header the shader and the host both include
// (docs/architecture.md, "Shared declarations"); the host gives each binding with its name.
#pragma once

#include "msm/vk/common.h"
#include "msm/vk/resources.h"

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace msm::vk {

class Context;
struct GraphicsDesc; // graphics.h

// The type of descriptor at binding i of set 0 is the i-th entry of a program's binding list.
enum class Binding : uint8_t {
  storage_buffer, // layout(binding = i) buffer
  uniform_buffer, // layout(binding = i) uniform
  storage_image,  // layout(binding = i, <format>) uniform image2D
  sampled_image,  // layout(binding = i) uniform sampler2D (combined image + sampler)
};

// The value of one binding for dispatch(): a buffer range, or an image view in a layout (plus a
// sampler for Binding::SampledImage). Implicit from Buffer and Image, so `{input, output}` works.
struct Descriptor {
  union {
    VkDescriptorBufferInfo buffer;
    VkDescriptorImageInfo image;
  };
  Descriptor(VkBuffer b, VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE) : buffer{b, offset, range} {}
  Descriptor(const Buffer& b, VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE)
      : buffer{b.handle(), offset, range} {}
  Descriptor(VkImageView view, VkImageLayout layout, VkSampler sampler = VK_NULL_HANDLE)
      : image{sampler, view, layout} {}
  // GENERAL: the layout of storage images. For a SampledImage pass the layout and the sampler.
  Descriptor(const Image& i, VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL, VkSampler sampler = VK_NULL_HANDLE)
      : image{sampler, i.view(), layout} {}
};

// A binding by its number: the name a shared header declares, as the shader's layout(binding = ...).
struct BindingAt {
  uint32_t binding = 0;
  Binding type = Binding::storage_buffer;
};

// The positional list (entry i: binding i) of bindings given by number in any order. Precondition
// (std::invalid_argument otherwise): every number from 0 to the largest given exactly once.
std::vector<Binding> bindings_at(std::span<const BindingAt> bindings);
inline std::vector<Binding> bindings_at(std::initializer_list<BindingAt> bindings) {
  return bindings_at(std::span<const BindingAt>(bindings.begin(), bindings.size()));
}

// A descriptor for the binding of that number.
struct DescriptorAt {
  uint32_t binding = 0;
  Descriptor descriptor;
};

// The positional list (entry i: binding i) of descriptors given by number in any order; the same
// precondition as bindings_at.
std::vector<Descriptor> descriptors_at(std::span<const DescriptorAt> descriptors);
inline std::vector<Descriptor> descriptors_at(std::initializer_list<DescriptorAt> descriptors) {
  return descriptors_at(std::span<const DescriptorAt>(descriptors.begin(), descriptors.size()));
}

// One 32-bit specialization constant (int, uint, float bits or a bool as VkBool32) of a pipeline.
struct SpecConstant {
  uint32_t id = 0;
  uint32_t value = 0;
};

// A pipeline (compute, or graphics from graphics.h) with its push-descriptor layout.
class Program {
 public:
  VkPipeline pipeline() const noexcept { return pipeline_; }
  VkPipelineLayout layout() const noexcept { return layout_; }
  VkPipelineBindPoint bind_point() const noexcept { return bind_point_; }
  VkShaderStageFlags stages() const noexcept { return stages_; }            // of the descriptors and push constants
  VkDescriptorSetLayout set_layout() const noexcept { return set_layout_; } // null without bindings
  std::span<const Binding> bindings() const noexcept { return bindings_; }
  uint32_t push_constant_size() const noexcept { return push_constant_size_; }
  const std::string& name() const noexcept { return name_; }
  explicit operator bool() const noexcept { return bool(pipeline_); }

 private:
  friend Program create_program(const Context&, std::span<const uint32_t>, std::string_view, std::span<const Binding>,
                                uint32_t, std::span<const SpecConstant>);
  friend Program create_program_layout(const Context&, std::string_view, std::span<const Binding>, uint32_t,
                                       VkShaderStageFlags, VkPipelineBindPoint);
  friend void bind_program(VkCommandBuffer, const Program&, std::span<const Descriptor>, std::span<const std::byte>);
  friend void dispatch(VkCommandBuffer, const Program&, uint32_t, uint32_t, uint32_t, std::span<const Descriptor>,
                       std::span<const std::byte>);
  friend Program create_graphics_program(const Context&, const GraphicsDesc&);
  std::string name_;
  std::vector<Binding> bindings_;
  uint32_t push_constant_size_ = 0;
  PFN_vkCmdPushDescriptorSetWithTemplateKHR push_descriptors_ = nullptr;
  VkShaderStageFlags stages_ = VK_SHADER_STAGE_COMPUTE_BIT;
  VkPipelineBindPoint bind_point_ = VK_PIPELINE_BIND_POINT_COMPUTE;
  // Declaration order is creation order; destruction runs in reverse.
  Unique<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout> set_layout_;
  Unique<VkPipelineLayout, vkDestroyPipelineLayout> layout_;
  Unique<VkDescriptorUpdateTemplate, vkDestroyDescriptorUpdateTemplate> template_;
  Unique<VkPipeline, vkDestroyPipeline> pipeline_;
};

// The specialization constants of one pipeline stage: those of the shared headers
// (include/msm/shared.h) — msm_fused_fma (id MSM_SPEC_FUSED_FMA_ID) = ctx.useNativeFma() — plus
// any given. create_program sets them on every pipeline; a pipeline created elsewhere passes info()
// as each stage's pSpecializationInfo. Ids that a shader does not declare are ignored, so every
// stage can take it. info() points into this object: keep it alive until the pipeline is created.
// Precondition: the extra ids are distinct and not MSM_SPEC_FUSED_FMA_ID.
class SharedSpecialization {
 public:
  explicit SharedSpecialization(const Context& ctx, std::span<const SpecConstant> extra = {});
  SharedSpecialization(const SharedSpecialization&) = delete;
  SharedSpecialization& operator=(const SharedSpecialization&) = delete;
  const VkSpecializationInfo* info() const noexcept { return &info_; }
  bool native_fma() const noexcept { return values_[0] != VK_FALSE; }

 private:
  std::vector<uint32_t> values_; // [0]: msm_fused_fma as a VkBool32
  std::vector<VkSpecializationMapEntry> entries_;
  VkSpecializationInfo info_{};
};

// A compute pipeline from SPIR-V with entry point "main", specialized with SharedSpecialization. The push-constant range is
// [0, push_constant_size) for the compute stage (none if 0). Preconditions (std::invalid_argument
// otherwise): SPIR-V words start with the magic number; push_constant_size is a multiple of 4 and at
// most maxPushConstantsSize; bindings.size() <= maxPushDescriptors. That the list matches the
// shader's declarations is checked by the validation layer, not here.
// `constants` are further specialization constants (SharedSpecialization).
Program create_program(const Context& ctx, std::span<const uint32_t> spirv, std::string_view name,
                       std::span<const Binding> bindings, uint32_t push_constant_size = 0,
                       std::span<const SpecConstant> constants = {});
// The same from an embedded shader (see shaders.h), looked up by name, with its bindings by number.
Program create_program(const Context& ctx, std::string_view shader, std::initializer_list<BindingAt> bindings,
                       uint32_t push_constant_size = 0, std::initializer_list<SpecConstant> constants = {});

// The layout of a program without its pipeline (for pipeline kinds built elsewhere, graphics.h):
// descriptors and push constants visible to `stages`. Preconditions as for create_program.
Program create_program_layout(const Context& ctx, std::string_view name, std::span<const Binding> bindings,
                              uint32_t push_constant_size, VkShaderStageFlags stages, VkPipelineBindPoint bind_point);

// Binds the pipeline at its bind point, pushes one descriptor per binding and the push constants
// (preconditions as for dispatch); draws or dispatches follow.
void bind_program(VkCommandBuffer cmd, const Program& program, std::span<const Descriptor> bindings,
                  std::span<const std::byte> push_constants = {});
inline void bind_program(VkCommandBuffer cmd, const Program& program, std::initializer_list<DescriptorAt> bindings,
                         std::span<const std::byte> push_constants = {}) {
  bind_program(cmd, program, descriptors_at(bindings), push_constants);
}
template <class PushConstants>
requires(
    std::is_standard_layout_v<PushConstants>&& std::is_trivially_destructible_v<PushConstants> &&
    !std::is_convertible_v<const PushConstants&,
                           std::span<const std::byte>>) void bind_program(VkCommandBuffer cmd, const Program& program,
                                                                          std::initializer_list<DescriptorAt> bindings,
                                                                          const PushConstants& push_constants) {
  bind_program(cmd, program, descriptors_at(bindings), std::as_bytes(std::span(&push_constants, 1)));
}

// Binds the pipeline, pushes one descriptor per binding and the push constants, and dispatches
// groups_x * groups_y * groups_z workgroups. Preconditions (std::invalid_argument otherwise, nothing
// recorded): one descriptor per binding, push_constants.size() == program.pushConstantSize(). The
// resources are in the layouts given and synchronized by the caller (the barrier helpers of
// commands.h); cmd is recording, outside a render pass.
void dispatch(VkCommandBuffer cmd, const Program& program, uint32_t groups_x, uint32_t groups_y, uint32_t groups_z,
              std::span<const Descriptor> bindings, std::span<const std::byte> push_constants = {});

inline void dispatch(VkCommandBuffer cmd, const Program& program, uint32_t groups_x, uint32_t groups_y,
                     uint32_t groups_z, std::initializer_list<DescriptorAt> bindings = {},
                     std::span<const std::byte> push_constants = {}) {
  dispatch(cmd, program, groups_x, groups_y, groups_z, descriptors_at(bindings), push_constants);
}

// Push constants given as one struct (its bytes, padding included, must match the shader's block).
// Standard layout rather than trivially copyable: GLM_FORCE_CTOR_INIT (msm::scene) gives glm types
// user-provided copies, yet their bytes are all there is to them.
template <class PushConstants>
requires(std::is_standard_layout_v<PushConstants>&& std::is_trivially_destructible_v<PushConstants> &&
         !std::is_convertible_v<const PushConstants&,
                                std::span<const std::byte>>) void dispatch(VkCommandBuffer cmd, const Program& program,
                                                                           uint32_t groups_x, uint32_t groups_y,
                                                                           uint32_t groups_z,
                                                                           std::initializer_list<DescriptorAt> bindings,
                                                                           const PushConstants& push_constants) {
  dispatch(cmd, program, groups_x, groups_y, groups_z, descriptors_at(bindings),
           std::as_bytes(std::span(&push_constants, 1)));
}

// Workgroups needed for `threads` invocations with `local_size` per group: ceil(threads / local_size).
constexpr uint32_t group_count(uint32_t threads, uint32_t local_size) {
  return (threads + local_size - 1) / local_size;
}

} // namespace msm::vk
