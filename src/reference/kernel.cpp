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
  if (size < 1 || size > MSM_FILTER_MAX_TAPS || size % 2 == 0)
    throw std::invalid_argument(fmt::format("filter size {} must be odd and in [1, {}]", size, MSM_FILTER_MAX_TAPS));
  if (!msm_filter_valid(size, float(sigma)) || !std::isfinite(sigma))
    throw std::invalid_argument(fmt::format("filter sigma {} must be finite and in [{}, {}] texels", sigma,
                                            MSM_FILTER_MIN_SIGMA, MSM_FILTER_MAX_SIGMA));
  // The renderer's weights exactly (float, msm/filter.h); kept in double for the sampling.
  for (int k = 0; k < size; ++k) weights_.push_back(double(msm_gaussian_weight(k, size, float(sigma))));
  for (double w : weights_) total_ += w;
  cumulative_.push_back(0.0);
  for (double w : weights_) cumulative_.push_back(cumulative_.back() + w / total_);
  cumulative_.back() = 1.0;
}

double FilterKernel::density(double s) const {
  double d = 0.0;
  for (int i = 0; i < size_; ++i) d += weights_[i] * std::max(0.0, 1.0 - std::abs(s - (i - radius())));
  return d / total_;
}

double FilterKernel::cdf(double s) const {
  double c = 0.0;
  for (int i = 0; i < size_; ++i) c += weights_[i] * tent_cdf(s - (i - radius()));
  return c / total_;
}

double FilterKernel::sample(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  int i = 0;
  while (i + 1 < size_ && u >= cumulative_[i + 1]) ++i;
  const double local = std::clamp((u - cumulative_[i]) / (weights_[i] / total_), 0.0, 1.0);
  return (i - radius()) + tent_inverse(local);
}

} // namespace msm::reference
