#include "frame_targets.h"

#include "msm/techniques.h"

#include <bit>
#include <fmt/format.h>

namespace msm::render {
namespace {

void require(const vk::Context& ctx, VkFormat format, VkFormatFeatureFlags features, std::string_view why) {
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), format, &props);
  if ((props.optimalTilingFeatures & features) != features)
    throw RenderError(fmt::format("{} does not support format {} for {}", ctx.info().name, int(format), why));
}

bool has(const vk::Context& ctx, VkFormat format, VkFormatFeatureFlags features) {
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), format, &props);
  return (props.optimalTilingFeatures & features) == features;
}

} // namespace

namespace {
VkFormat two_channels(VkFormat f) {
  switch (f) {
  case VK_FORMAT_R16G16B16A16_UNORM: return VK_FORMAT_R16G16_UNORM;
  case VK_FORMAT_R16G16B16A16_SFLOAT: return VK_FORMAT_R16G16_SFLOAT;
  case VK_FORMAT_R32G32B32A32_SFLOAT: return VK_FORMAT_R32G32_SFLOAT;
  default: return VK_FORMAT_UNDEFINED;
  }
}
} // namespace

bool FrameConfig::split_rg() const {
  return translucent && technique && two_channels(VkFormat(technique->formats[0])) != VK_FORMAT_UNDEFINED;
}

std::array<int, 2> FrameConfig::formats() const {
  if (!technique) return {0, 0};
  if (split_rg()) {
    int f = two_channels(VkFormat(technique->formats[0]));
    return {f, f};
  }
  return technique->formats;
}

int FrameConfig::moment_images() const {
  std::array<int, 2> f = formats();
  return (f[0] != 0) + (f[1] != 0);
}

VkExtent2D extent(const vk::Image& image) { return {image.width(), image.height()}; }

FrameTargets::FrameTargets(const vk::Context& ctx, const FrameConfig& c) : config(c) {
  uint32_t shadow = uint32_t(c.shadow_size);
  auto samples = VkSampleCountFlagBits(c.msaa);
  if (!vk::supports_attachment(ctx, VK_FORMAT_D16_UNORM, samples))
    throw RenderError(
        fmt::format("{} cannot render 16-bit depth with {}x MSAA; use --msaa 1 or 4", ctx.info().name, c.msaa));
  VkImageUsageFlags depth_usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  if (c.msaa == 1) depth_usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  shadow_depth = vk::create_image(
      ctx,
      {.width = shadow, .height = shadow, .format = VK_FORMAT_D16_UNORM, .usage = depth_usage, .samples = samples});

  VkFormatFeatureFlags blit = VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT;
  // The non-linear maps are never interpolated by the hardware (and have no mips): they are
  // decoded first.
  bool nonlinear = msm_technique_is_nonlinear(c.technique ? c.technique->id : 0);
  bool soft = msm_technique_is_soft(c.technique ? c.technique->id : 0);
  bool can_mip = c.mipmaps && !nonlinear && !soft;
  for (int i = 0; i < c.moment_images(); ++i) {
    auto format = VkFormat(c.formats()[size_t(i)]);
    VkFormatFeatureFlags need = VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
    if (!nonlinear) need |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
    if (c.translucent) need |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT;
    require(ctx, format, need, "moment images (storage, sampling)");
    can_mip = can_mip && has(ctx, format, blit);
  }
  mip_levels = can_mip ? uint32_t(std::bit_width(shadow)) : 1u;
  const VkImageUsageFlags moment_usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                         VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                         (c.translucent ? VkImageUsageFlags(VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) : 0u);
  const int c_channels = c.channels();
  for (int i = 0; i < c.moment_images(); ++i) {
    moments[size_t(i)] = vk::create_image(ctx, {.width = shadow,
                                                .height = shadow,
                                                .format = VkFormat(c.formats()[size_t(i)]),
                                                .usage = moment_usage,
                                                .mip_levels = mip_levels});
    moments_mip0[size_t(i)] = vk::create_image_view(ctx, moments[size_t(i)].handle(), moments[size_t(i)].format(),
                                                    VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D, 0, 1);
    for (int c = 1; c < c_channels; ++c) {
      vk::Image& image = colour_moments[size_t(c - 1)][size_t(i)];
      image = vk::create_image(ctx, {.width = shadow,
                                     .height = shadow,
                                     .format = moments[size_t(i)].format(),
                                     .usage = moment_usage,
                                     .mip_levels = mip_levels});
      colour_moments_mip0[size_t(c - 1)][size_t(i)] = vk::create_image_view(
          ctx, image.handle(), image.format(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_VIEW_TYPE_2D, 0, 1);
    }
    if (c.taps > 1 && !c.one_pass && !soft)
      blur_temp[size_t(i)] = vk::create_image(ctx, {.width = shadow,
                                                    .height = shadow,
                                                    .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                                    .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
  }

  if (soft)
    for (int i = 0; i < c.moment_images(); ++i) {
      // Two moments per texel (vssm; mssm6's second image) need only RG32_UINT.
      bool two = c.formats()[size_t(i)] == VK_FORMAT_R32G32_SFLOAT;
      sat_tables[size_t(i)] =
          vk::create_image(ctx, {.width = shadow,
                                 .height = shadow,
                                 .format = two ? VK_FORMAT_R32G32_UINT : VK_FORMAT_R32G32B32A32_UINT,
                                 .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
    }
  uint32_t w = uint32_t(c.width), h = uint32_t(c.height);
  color = vk::create_image(ctx, {.width = w,
                                 .height = h,
                                 .format = VK_FORMAT_R8G8B8A8_SRGB,
                                 .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
  shadow_buffer =
      vk::create_image(ctx, {.width = w,
                             .height = h,
                             .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                             .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
  camera_depth = vk::create_image(
      ctx,
      {.width = w, .height = h, .format = VK_FORMAT_D32_SFLOAT, .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT});
  point_sampler = vk::create_sampler(ctx, VK_FILTER_NEAREST);
  moment_sampler = vk::create_sampler(ctx, VK_FILTER_LINEAR);
}

} // namespace msm::render
