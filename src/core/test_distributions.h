// Random depth distributions for the tests of the shared math, in double precision.
// Continuous distributions are represented by a fine midpoint quadrature (512 atoms), which is
// what a filter kernel over a sloped surface produces anyway.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace msm::test {

struct Distribution {
  std::vector<double> z; // depths
  std::vector<double> w; // weights, sum 1
};

// 'count' Diracs with random depths in [lo, hi] and random weights (none below 1%).
Distribution random_diracs(std::mt19937_64& rng, int count, double lo, double hi);
// A mixture of 1-3 bumps (uniform or truncated Gaussian) inside [lo, hi], discretized.
Distribution random_continuous(std::mt19937_64& rng, double lo, double hi);
// Either of the above (half each), with 1 to 8 Diracs.
Distribution random_distribution(std::mt19937_64& rng, double lo, double hi);

double cdf_less(const Distribution& d, double zf);       // Z(z < zf)
double cdf_less_equal(const Distribution& d, double zf); // Z(z <= zf)

// (b0 = 1, b1, ..., bm) of d.
std::vector<double> power_moments(const Distribution& d, int m);
// (E sin 2πz, E cos 2πz, E sin 4πz, E cos 4πz) of a distribution on [0,1].
std::vector<double> trig_moments(const Distribution& d);
// b1..b4 rounded to float.
glm::vec4 moments4f(const Distribution& d);

// Absolute errors collected over many cases, for quantiles and the maximum.
struct ErrorStats {
  std::vector<double> errors;
  void add(double e) { errors.push_back(std::abs(e)); }
  double quantile(double q) {
    std::sort(errors.begin(), errors.end());
    return errors.empty() ? 0.0 : errors[size_t(q * double(errors.size() - 1))];
  }
  double max() { return quantile(1.0); }
  // Prints "[label] n N pQ E max M" and expects at least min_count errors, their q-quantile below
  // quantile_bound and their maximum below max_bound.
  void expect_below(const char* label, std::size_t min_count, double q, double quantile_bound, double max_bound) {
    std::printf("[%s] n %zu p%.0f %.2e max %.2e\n", label, errors.size(), 100.0 * q, quantile(q), max());
    EXPECT_GE(errors.size(), min_count) << label;
    EXPECT_LT(quantile(q), quantile_bound) << label;
    EXPECT_LT(max(), max_bound) << label;
  }
};

} // namespace msm::test
