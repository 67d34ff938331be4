#include "pass.h"

#include <fmt/format.h>

#include <algorithm>
#include <span>

namespace msm::render {

namespace {

std::string temp_name(int channel, int i) { return fmt::format("blur_temp{}.{}", i, channel); }

// Between the two directions, in float, read with bilinear fetches.
constexpr VkFormat kTempFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

} // namespace

std::vector<vk::SpecConstant> blur_constants(int taps, bool bilinear, bool mip1) {
  static_assert(MSM_BLUR_MAX_PAIRS == (MSM_FILTER_MAX_TAPS / 2 + 1) / 2);
  return {{MSM_BLUR_SPEC_ID, uint32_t(msm_filter_pairs(taps))},
          {uint32_t(MSM_BLUR_SPEC_ID + 2 + 2 * MSM_BLUR_MAX_PAIRS), bilinear ? 1u : 0u},
          {uint32_t(MSM_BLUR_SPEC_ID + 3 + 2 * MSM_BLUR_MAX_PAIRS), mip1 ? 1u : 0u}};
}

BlurKernel blur_kernel(int taps, float sigma) {
  BlurKernel k{};
  auto set = [&](int i, float value) { k.values[i / 4][i % 4] = value; };
  set(0, msm_filter_weight_at(0, taps, sigma));
  for (int j = 1; j <= MSM_BLUR_MAX_PAIRS; ++j) {
    set(2 * j - 1, msm_filter_pair_offset(j, taps, sigma));
    set(2 * j, msm_filter_pair_weight(j, taps, sigma)); // 0 beyond the kernel
  }
  return k;
}

namespace {
// The 32-bit float maps keep their precision (a bilinear fetch's fraction is as coarse as its
// coordinate: RenderTest.OnePassFilterEqualsTheThreePassFilter); the others take half the fetches.
bool bilinear_blur(const FrameConfig& config) {
  for (VkFormat f : config.formats())
    if (f == VK_FORMAT_R32_SFLOAT || f == VK_FORMAT_R32G32_SFLOAT || f == VK_FORMAT_R32G32B32A32_SFLOAT) return false;
  return true;
}
} // namespace

void BlurPass::prepare(const PassResources& r) {
  const vk::Context& ctx = r.programs.context();
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), kTempFormat, &props);
  if (!(props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
    throw RenderError(fmt::format("the blur needs linear filtering of RGBA32F images; {} has none (use "
                                  "--filter-mode one-pass or --filter 1)",
                                  ctx.info().name));
  const std::vector<vk::Binding> bindings = vk::bindings_at({{MSM_BINDING_BLUR_SOURCE, vk::Binding::sampled_image},
                                                             {MSM_BINDING_BLUR_TARGET, vk::Binding::storage_image},
                                                             {MSM_BINDING_BLUR_TARGET_MIP1, vk::Binding::storage_image},
                                                             {MSM_BINDING_BLUR_KERNELS, vk::Binding::storage_buffer}});
  bool bilinear = bilinear_blur(config_);
  program_ =
      &r.programs.compute("blur.comp", bindings, sizeof(ImagePassPush), blur_constants(config_.taps, bilinear, false));
  vertical_program_ = config_.blur_writes_mip1() ? &r.programs.compute("blur.comp", bindings, sizeof(ImagePassPush),
                                                                       blur_constants(config_.taps, bilinear, true))
                                                 : program_;
  kernels_ = vk::create_buffer(ctx, sizeof(BlurKernel) * std::size_t(std::max(config_.lights, 1)),
                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
}

void BlurPass::reflect(PassBuilder& b) const {
  for (int i = 0; i < config_.moment_images(); ++i) {
    b.modify(moment_image(channel_, i), use::compute_general());
    // One layer, reused light after light.
    b.scratch(temp_name(channel_, i), {.format = kTempFormat,
                                       .width = uint32_t(config_.shadow_size),
                                       .height = uint32_t(config_.shadow_size),
                                       .extra_usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
  }
}

void BlurPass::execute(const PassContext& c) const {
  int size = config_.shadow_size;
  uint32_t groups = vk::group_count(uint32_t(size), 8);
  constexpr VkImageLayout general = VK_IMAGE_LAYOUT_GENERAL;
  VkSampler sampler = bilinear_blur(config_) ? c.frame.linear_sampler : c.frame.point_sampler;
  constexpr VkPipelineStageFlags2 compute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  // Each layer's kernel (LightUniforms::kernel: a cascade's scaled to the world width of the
  // first's); the frame is submitted and waited for before the next is recorded.
  std::span<BlurKernel> kernels = kernels_.mapped<BlurKernel>();
  for (int l = 0; l < config_.lights; ++l) {
    const glm::vec4& k = c.frame.light_data[size_t(l)].kernel;
    kernels[size_t(l)] = blur_kernel(int(k.y), k.x);
  }
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    for (int i = 0; i < config_.moment_images(); ++i) {
      VkImageView moments = c.image(moment_image(channel_, i)).layer_mip0_views[size_t(l)];
      const GraphImage& temp = c.image(temp_name(channel_, i));
      // The scratch image's earlier contents (the previous light's) are not needed.
      vk::pipeline_barrier(c.cmd, vk::image_barrier(temp.image.handle(), VK_IMAGE_ASPECT_COLOR_BIT, compute,
                                                    VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                                                    compute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, general));
      vk::Descriptor temp_storage(temp.layer_views[0], general);
      vk::dispatch(c.cmd, *program_, groups, groups, 1,
                   {{MSM_BINDING_BLUR_SOURCE, vk::Descriptor(moments, general, sampler)},
                    {MSM_BINDING_BLUR_TARGET, temp_storage},
                    {MSM_BINDING_BLUR_TARGET_MIP1, temp_storage},
                    {MSM_BINDING_BLUR_KERNELS, vk::Descriptor(kernels_)}},
                   ImagePassPush{glm::ivec4(size, size, 0, l)});
      vk::pipeline_barrier(
          c.cmd,
          vk::memory_barrier(compute, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                             compute, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT));
      // With mips: mip 1 too, each invocation a 2 x 2 block (the mipmap pass starts at mip 2).
      bool mip1 = config_.blur_writes_mip1();
      const GraphImage& target = c.image(moment_image(channel_, i));
      uint32_t vertical_groups = mip1 ? vk::group_count(uint32_t(size / 2), 8) : groups;
      vk::dispatch(
          c.cmd, *vertical_program_, vertical_groups, vertical_groups, 1,
          {{MSM_BINDING_BLUR_SOURCE, vk::Descriptor(temp.layer_views[0], general, sampler)},
           {MSM_BINDING_BLUR_TARGET, vk::Descriptor(moments, general)},
           {MSM_BINDING_BLUR_TARGET_MIP1, vk::Descriptor(mip1 ? target.layer_mip1_views[size_t(l)] : moments, general)},
           {MSM_BINDING_BLUR_KERNELS, vk::Descriptor(kernels_)}},
          ImagePassPush{glm::ivec4(size, size, 1, l)});
    }
    c.end_light();
  }
}

} // namespace msm::render
