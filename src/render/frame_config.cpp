#include "frame_config.h"

#include <fmt/format.h>

namespace msm::render {
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

VkFormat vk_format(TexelFormat format) {
  switch (format) {
  case TexelFormat::none: return VK_FORMAT_UNDEFINED;
  case TexelFormat::r32_float: return VK_FORMAT_R32_SFLOAT;
  case TexelFormat::rg16_unorm: return VK_FORMAT_R16G16_UNORM;
  case TexelFormat::rg16_float: return VK_FORMAT_R16G16_SFLOAT;
  case TexelFormat::rg32_float: return VK_FORMAT_R32G32_SFLOAT;
  case TexelFormat::rgba16_unorm: return VK_FORMAT_R16G16B16A16_UNORM;
  case TexelFormat::rgba16_float: return VK_FORMAT_R16G16B16A16_SFLOAT;
  case TexelFormat::rgba32_float: return VK_FORMAT_R32G32B32A32_SFLOAT;
  case TexelFormat::r32_uint: return VK_FORMAT_R32_UINT;
  }
  return VK_FORMAT_UNDEFINED;
}

bool FrameConfig::split_rg() const {
  return translucent && technique && two_channels(vk_format(technique->formats[0])) != VK_FORMAT_UNDEFINED;
}

std::array<VkFormat, 2> FrameConfig::formats() const {
  if (!technique) return {VK_FORMAT_UNDEFINED, VK_FORMAT_UNDEFINED};
  if (split_rg()) {
    VkFormat f = two_channels(vk_format(technique->formats[0]));
    return {f, f};
  }
  return {vk_format(technique->formats[0]), vk_format(technique->formats[1])};
}

int FrameConfig::moment_images() const {
  std::array<VkFormat, 2> f = formats();
  return (f[0] != VK_FORMAT_UNDEFINED) + (f[1] != VK_FORMAT_UNDEFINED);
}

FrameConfig FrameConfig::resampling_moments() const {
  FrameConfig m;
  m.technique = &find_technique(kResamplingMomentsTechnique);
  m.width = width;
  m.height = height;
  m.shadow_size = shadow_size;
  m.msaa = msaa;
  m.taps = taps;
  m.sigma = sigma;
  m.lights = lights;
  m.mip_levels = resampling_mips;
  return m;
}

std::string moment_image(int channel, int i) {
  static const char* suffix[] = {"", ".g", ".b"};
  return fmt::format("moments{}{}", i, suffix[channel]);
}

std::string sat_table(int i) { return fmt::format("sat_table{}", i); }

} // namespace msm::render
