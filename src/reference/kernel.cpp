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

// Inverse of tent_cdf on [0, 1]: sqrt(2u) - 1 below 1/2, 1 - sqrt(2 (1 - u)) above, written
// without a branch (abs, copysign), because u is random: GCC compiled the selects of the plain
// form, and std::min, into branches, whose mispredictions were most of the ray tracer's sampling
// time (callgrind --branch-sim). 1/2 - |u - 1/2| is exactly 1 - u above 1/2 and u within 2^-54
// below.
double tent_inverse(double u) {
  const double h = u - 0.5;
  return std::copysign(1.0 - std::sqrt(2.0 * (0.5 - std::abs(h))), h);
}

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
  for (double w : weights_) inverse_share_.push_back(total_ / w);
  for (int i = 1; i <= size_; ++i) upper_.push_back(i < size_ ? cumulative_[size_t(i)] : 2.0); // u <= 1 < 2
  // 8 buckets per tap: u's tap is then the bucket's first tap or, for the few buckets that
  // straddle a tap's end, mostly the next one; the search from tap 0 took radius() steps.
  const int buckets = 8 * size_;
  for (int j = 0, i = 0; j < buckets; ++j) {
    while (double(j) / buckets >= upper_[size_t(i)]) ++i;
    first_tap_.push_back(i);
  }
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
  u = std::min(std::max(u, 0.0), 1.0); // minsd/maxsd (std::clamp became branches)
  const int buckets = int(first_tap_.size());
  // Bucket floor(u · buckets): its first tap, one step on without a branch, further (rarely: taps
  // lighter than a bucket) with one; and back where the rounding of u · buckets put u a hair
  // before the bucket's start (never, in practice). The same tap as the search from tap 0.
  int i = first_tap_[size_t(std::min(int(u * buckets), buckets - 1))];
  i += int(u >= upper_[size_t(i)]);
  while (u >= upper_[size_t(i)]) ++i;
  while (i > 0 && u < upper_[size_t(i) - 1]) --i;
  const double local = std::min(std::max((u - cumulative_[size_t(i)]) * inverse_share_[size_t(i)], 0.0), 1.0);
  return (i - radius()) + tent_inverse(local);
}

} // namespace msm::reference
