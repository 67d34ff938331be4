// Order statistics of measurements (C++ only), one definition for the tools' tables: the
// nearest-rank quantile, the median being its q = 0.5.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace msm::util {

// The element at rank round(q (n - 1)) of the sorted values. Precondition: values not empty,
// q in [0, 1]; else std::invalid_argument.
inline double quantile(std::vector<double> values, double q) {
  if (values.empty() || !(q >= 0.0 && q <= 1.0)) throw std::invalid_argument("quantile: no values or q outside [0, 1]");
  auto k = std::ptrdiff_t(std::floor(q * double(values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[size_t(k)];
}

inline double median(std::vector<double> values) { return quantile(std::move(values), 0.5); }

} // namespace msm::util
