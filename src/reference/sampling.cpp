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

glm::dvec2 SampleSet::point(int i, Rng& rng) const {
  const double a = rng.uniform(), b = rng.uniform();
  if (i < grid_ * grid_) {
    // Jittered cell (i mod m, i div m) of the m x m grid. The row without an integer division (the
    // slowest instruction per sample): (i + 0.5) / m is at least 0.5 / m from an integer and its
    // rounding error below m · 2^-52, so the floor is exact for m < 2^25.
    const double inv = inverse_grid_;
    const int row = int((i + 0.5) * inv), column = i - row * grid_;
    return {std::min((column + a) * inv, std::nextafter(1.0, 0.0)),
            std::min((row + b) * inv, std::nextafter(1.0, 0.0))};
  }
  return {a, b};
}

glm::dvec2 concentric_disc(glm::dvec2 u) {
  const double a = 2.0 * u.x - 1.0, b = 2.0 * u.y - 1.0;
  // Shirley-Chiu: r = a, φ = π/4 · b/a where |a| > |b|; else r = b, φ = π/2 − π/4 · a/b, whose
  // cosine and sine are the sine and cosine of x = π/4 · a/b. So one angle x, |x| <= π/4, and
  // selects, not branches (which way a sample goes is random), and no libm call: sin and cos of x
  // by their Taylor series to x^15 and x^16, nested (Horner); the first terms left out are below
  // 5e-17 and 3e-18, under half an ulp of the results.
  const bool wide = std::abs(a) > std::abs(b);
  const double r = wide ? a : b;
  if (r == 0.0) return {0.0, 0.0}; // a = b = 0
  const double x = std::numbers::pi / 4.0 * ((wide ? b : a) / r), x2 = x * x;
  double s = 1.0, c = 1.0;
  for (int k = 8; k >= 1; --k) {
    c = 1.0 - x2 * (1.0 / ((2 * k - 1) * (2 * k))) * c;
    if (k < 8) s = 1.0 - x2 * (1.0 / ((2 * k) * (2 * k + 1))) * s;
  }
  s *= x;
  return wide ? glm::dvec2(r * c, r * s) : glm::dvec2(r * s, r * c);
}

} // namespace msm::reference::detail
