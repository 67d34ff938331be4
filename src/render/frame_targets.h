// The images of one frame configuration (sizes, MSAA, technique formats), reused while the
// configuration stays the same.
#pragma once

#include "msm/render/renderer.h"
#include "msm/vk/vk.h"

#include <array>

namespace msm::render {

struct FrameConfig {
  const Technique* technique = nullptr;
  int width = 0, height = 0, shadow_size = 0, msaa = 1, taps = 1;
  bool mipmaps = true;
  bool one_pass = false; // one_pass_filter instead of moment_resolve + blur
  // Translucent occluders are blended into the map (JCGT §3): a four-channel technique then
  // stores its moments as two RG images, because the blend factor is the fragment's alpha.
  bool translucent = false;
  // Coloured translucent shadows (JCGT §3): one set of moment images per colour channel, each
  // blended with the channel's opacity α (1 − transmission colour); only with translucent.
  bool coloured = false;
  bool operator==(const FrameConfig&) const = default;
  bool split_rg() const;                            // translucent and four channels in one image
  std::array<int, 2> formats() const;               // of the moment images as allocated
  int moment_images() const;                        // 0 (depth-based), 1 or 2 (6MSM, split_rg)
  int channels() const { return coloured ? 3 : 1; } // sets of moment images
};

struct FrameTargets {
  FrameConfig config;
  vk::Image shadow_depth;                    // D16, config.msaa samples
  std::array<vk::Image, 2> moments;          // the technique's formats, mip_levels mips
  std::array<vk::ImageView, 2> moments_mip0; // mip 0 alone: what resolve and blur write (GENERAL)
  // Coloured translucency: the moment images of the green and blue channels (moments: red).
  std::array<std::array<vk::Image, 2>, 2> colour_moments;
  std::array<std::array<vk::ImageView, 2>, 2> colour_moments_mip0;
  const vk::Image& moment_image(int channel, int i) const {
    return channel == 0 ? moments[size_t(i)] : colour_moments[size_t(channel - 1)][size_t(i)];
  }
  VkImageView moment_mip0(int channel, int i) const {
    return channel == 0 ? moments_mip0[size_t(i)] : colour_moments_mip0[size_t(channel - 1)][size_t(i)];
  }
  std::array<vk::Image, 2> blur_temp; // RGBA32F, between the two blur directions
  vk::Image color;                    // RGBA8 sRGB
  vk::Image shadow_buffer;            // RGBA32F: visibility per colour channel, coverage
  vk::Image camera_depth;             // D32
  // Summed-area tables of the moment images (soft shadows only; two for mssm6): RGBA32_UINT, or
  // RG32_UINT for an RG image (sampled as uvec4(r, g, 0, 1): only r, g are summed).
  std::array<vk::Image, 2> sat_tables;
  uint32_t mip_levels = 1;
  vk::Sampler point_sampler, moment_sampler;

  // Throws RenderError where the device lacks a format feature the configuration needs.
  FrameTargets(const vk::Context& ctx, const FrameConfig& config);
};

VkExtent2D extent(const vk::Image& image);

} // namespace msm::render
