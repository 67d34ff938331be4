// The continuous PCF footprint (msm/reference/kernel.h).
#include "msm/reference/kernel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace msm::reference {
namespace {

// Cumulative distribution of the tent max(0, 1 - |u|).
double tent_cdf(double u) {
  if (u <= -1.0) return 0.0;
  if (u >= 1.0) return 1.0;
  return u < 0.0 ? 0.5 * (u + 1.0) * (u + 1.0) : 1.0 - 0.5 * (1.0 - u) * (1.0 - u);
}

// Inverse of tent_cdf on [0, 1].
double tent_inverse(double u) { return u < 0.5 ? std::sqrt(2.0 * u) - 1.0 : 1.0 - std::sqrt(2.0 * (1.0 - u)); }

} // namespace

FilterKernel::FilterKernel(int size, double sigma) : size_(size), sigma_(sigma) {
  if (size < 1 || size > kMaxSize || size % 2 == 0)
    throw std::invalid_argument(fmt::format("filter size {} must be odd and in [1, {}]", size, kMaxSize));
  if (!std::isfinite(sigma) || !(sigma > 0.0) || sigma > 1e4)
    throw std::invalid_argument(fmt::format("filter sigma {} must be finite, > 0 and <= 1e4 texels", sigma));
  const int r = radius();
  double total = 0.0;
  for (int k = -r; k <= r; ++k) {
    weights_.push_back(std::exp(-double(k) * k / (2.0 * sigma * sigma)));
    total += weights_.back();
  }
  cumulative_.push_back(0.0);
  for (double& w : weights_) {
    w /= total;
    cumulative_.push_back(cumulative_.back() + w);
  }
  cumulative_.back() = 1.0;
}

double FilterKernel::density(double s) const {
  double d = 0.0;
  for (int i = 0; i < size_; ++i) d += weights_[i] * std::max(0.0, 1.0 - std::abs(s - (i - radius())));
  return d;
}

double FilterKernel::cdf(double s) const {
  double c = 0.0;
  for (int i = 0; i < size_; ++i) c += weights_[i] * tent_cdf(s - (i - radius()));
  return c;
}

double FilterKernel::sample(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  int i = 0;
  while (i + 1 < size_ && u >= cumulative_[i + 1]) ++i;
  const double local = std::clamp((u - cumulative_[i]) / weights_[i], 0.0, 1.0);
  return (i - radius()) + tent_inverse(local);
}

} // namespace msm::reference
