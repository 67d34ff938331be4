// msm::reference: the continuous footprint of the renderer's shadow-map filter (PCF), in texels.
//
// The renderer filters a shadow map of shadow_size x shadow_size texels with the discrete Gaussian
// of msm/filter.h (size x size taps, the product w_i w_j of its normalized 1D weights, computed by
// msm_gaussian_weight for both) and samples the result bilinearly. Bilinear sampling spreads each tap
// over a tent (hat) of half-width 1 texel per axis, so the continuous kernel of an offset
// o = (ox, oy) in texels is
//     K(o) = k(ox) k(oy),   k(s) = sum_k w_k tent(s - k),   tent(u) = max(0, 1 - |u|),
// a density (it integrates to 1). Sampling: pick the tap k with probability w_k, then add a
// triangular offset on [-1, 1] (the tent's density) - per axis, since K is separable.
//
// The offsets are in shadow-map texels of the light frustum of light_projection() * light_view():
// one texel is the frustum's width / shadow_size along light-space x and its height / shadow_size
// along light-space y (msm::reference::LightFrame).
#pragma once

#include "msm/filter.h"

#include <vector>

namespace msm::reference {

class FilterKernel {
 public:
  // msm_filter_valid(size, sigma) (size odd in [1, MSM_FILTER_MAX_TAPS], sigma in texels within
  // [MSM_FILTER_MIN_SIGMA, MSM_FILTER_MAX_SIGMA]); else std::invalid_argument.
  FilterKernel(int size = MSM_FILTER_DEFAULT_TAPS, double sigma = MSM_FILTER_DEFAULT_SIGMA);

  int size() const noexcept { return size_; }
  int radius() const noexcept { return (size_ - 1) / 2; }
  double sigma() const noexcept { return sigma_; }
  // The renderer's 1D weights w_k for k = -radius..radius (index k + radius): msm_gaussian_weight's
  // floats, which sum to 1 within their rounding (a few 1e-8).
  const std::vector<double>& weights() const noexcept { return weights_; }

  // The 1D marginal k(s) and its cumulative distribution K1(s) = integral of k up to s, with the
  // weights divided by their sum (a density that integrates to 1 in double precision).
  double density(double s) const;
  double cdf(double s) const;

  // Inverse-transform-like map of u in [0, 1) to a 1D offset distributed with density k:
  // the tap whose cumulative weight interval holds u, then the tent's inverse CDF of u rescaled
  // within that interval. Measure-preserving, so stratified u give stratified offsets per tap.
  // The ray tracer calls it twice per filtered sample: the tap is found through a table of
  // buckets of u (not a search from tap 0), and the rest has no conditional on u.
  double sample(double u) const;

 private:
  int size_;
  double sigma_;
  double total_ = 0.0;                       // sum of weights_
  std::vector<double> weights_, cumulative_; // cumulative_[i] = sum of weights_[0..i) / total_
  std::vector<double> inverse_share_;        // total_ / weights_[i]: u's scale within tap i
  std::vector<double> upper_;                // cumulative_[i + 1], 2 for the last tap (beyond any u)
  std::vector<int> first_tap_;               // per bucket [j, j + 1) / buckets of u: the tap at its start
};

} // namespace msm::reference
