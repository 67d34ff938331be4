// The renderer's blue-noise set: the texels msm_embed_blue_noise generated at build time.
#include "msm/noise/blue_noise.h"

#include "embedded_set.h"

namespace msm::noise {

const BlueNoise& blue_noise() {
  static const BlueNoise noise{embedded::kSize, embedded::kCount, embedded::kChannels,
                               std::vector<std::uint8_t>(embedded::kTexels, embedded::kTexels + embedded::kTexelCount)};
  return noise;
}

} // namespace msm::noise
