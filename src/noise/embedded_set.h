// The renderer's blue-noise set as embedded data: declared here, defined in the source file that
// msm_embed_blue_noise writes at build time (<build>/src/noise/generated/blue_noise_set.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

namespace msm::noise::embedded {

// generate_blue_noise(BlueNoiseParams{}) in the layout of BlueNoise (the generated file names the
// parameters in a comment).
extern const int kSize, kCount, kChannels;
extern const std::size_t kTexelCount;
extern const std::uint8_t kTexels[];

} // namespace msm::noise::embedded
