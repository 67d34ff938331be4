// Per-pixel generators and sample sets (see reference.h, "Samplers").
#include <cmath>
#include <numbers>

#include "internal.h"

namespace msm::reference::detail {

Rng pixel_rng(std::uint64_t seed, int x, int y, Effect effect) {
  // Hash the seed, the pixel and the effect into an independent-looking stream per pixel.
  std::uint64_t h = Rng(seed).next();
  h = Rng(h ^ (std::uint64_t(std::uint32_t(x)) | (std::uint64_t(std::uint32_t(y)) << 32))).next();
  return Rng(Rng(h ^ (0xD1B54A32D192ED03ull * (std::uint64_t(effect) + 1))).next());
}

SampleSet::SampleSet(Sampler sampler, int count) : sampler_(sampler), count_(count), grid_(0) {
  if (sampler_ == Sampler::stratified) {
    grid_ = int(std::sqrt(double(count)));
    while (grid_ * grid_ > count) --grid_;
    while ((grid_ + 1) * (grid_ + 1) <= count) ++grid_;
  }
  inverse_grid_ = grid_ > 0 ? 1.0 / grid_ : 0.0;
}

} // namespace msm::reference::detail
