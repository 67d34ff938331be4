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
}

glm::dvec2 SampleSet::point(int i, Rng& rng) const {
  const double a = rng.uniform(), b = rng.uniform();
  if (i < grid_ * grid_) {
    // Jittered cell (i mod m, i div m) of the m x m grid.
    const double inv = 1.0 / grid_;
    const int column = i % grid_, row = i / grid_;
    return {std::min((column + a) * inv, std::nextafter(1.0, 0.0)),
            std::min((row + b) * inv, std::nextafter(1.0, 0.0))};
  }
  return {a, b};
}

glm::dvec2 concentric_disc(glm::dvec2 u) {
  const double a = 2.0 * u.x - 1.0, b = 2.0 * u.y - 1.0;
  if (a == 0.0 && b == 0.0) return {0.0, 0.0};
  constexpr double quarter = std::numbers::pi / 4.0;
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = quarter * (b / a);
  } else {
    r = b;
    phi = 2.0 * quarter - quarter * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

} // namespace msm::reference::detail
