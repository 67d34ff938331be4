// The ray tracer's sampling internals (internal.h): the soft effect's single-precision disc map
// against the double-precision one, and the visible count's statistics against Welford's.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "internal.h"

namespace {

using namespace msm::reference::detail;

// Over a 513 x 513 grid of [0,1]^2 (its centre, edges and diagonals included), the float map is
// the double one to within 3 float ulps of 1 (3 · 2^-24: the float inputs' rounding, at most half
// an ulp each, plus the float arithmetic), stays in the unit disc as closely, and maps the centre
// to the centre.
TEST(reference_sampling, SinglePrecisionDiscMapIsTheDoubleOne) {
  constexpr int n = 512;
  const double ulp = std::ldexp(1.0, -24);
  double worst = 0.0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const glm::dvec2 u(std::min(double(i) / n, 1.0 - 0x1.0p-53), std::min(double(j) / n, 1.0 - 0x1.0p-53));
      const glm::dvec2 d = concentric_disc(u);
      const glm::vec2 f = concentric_disc(glm::vec2(u));
      worst = std::max({worst, std::abs(double(f.x) - d.x), std::abs(double(f.y) - d.y)});
      EXPECT_LE(glm::length(glm::dvec2(f)), 1.0 + 3.0 * ulp) << u.x << ", " << u.y;
    }
  EXPECT_LE(worst, 3.0 * ulp);
  EXPECT_GT(worst, 0.0); // the two precisions do differ: the comparison is not of one function
  EXPECT_EQ(concentric_disc(glm::vec2(0.5f)), glm::vec2(0.0f));
  // A whole half-plane of the square maps onto one half of the disc: the angle's quadrant is right.
  EXPECT_NEAR(concentric_disc(glm::vec2(1.0f, 0.5f)).x, 1.0f, 1e-7f);
  EXPECT_NEAR(concentric_disc(glm::vec2(0.5f, 0.0f)).y, -1.0f, 1e-7f);
  EXPECT_NEAR(concentric_disc(glm::vec2(1.0f, 1.0f)).x, float(std::sqrt(0.5)), 1e-7f);
}

// k ones of n samples: the mean and standard error that RunningStats accumulates one sample at a
// time, to within 1e-13 relative (Welford's rounding over up to 4096 steps).
TEST(reference_sampling, VisibleCountHasWelfordsStatistics) {
  for (int n : {1, 2, 3, 16, 255, 256, 4096})
    for (int k = 0; k <= n; k += std::max(1, n / 37)) {
      RunningStats welford;
      for (int i = 0; i < n; ++i) welford.add(i < k ? 1.0 : 0.0); // order does not matter beyond rounding
      const EffectResult a = monte_carlo_result(welford), b = monte_carlo_result(BinaryStats{n, k});
      EXPECT_NEAR(b.value, a.value, 1e-13 * std::max(a.value, 1e-300)) << k << " of " << n;
      EXPECT_NEAR(b.std_error, a.std_error, 1e-13 * std::max(a.std_error, 1e-300) + 1e-300) << k << " of " << n;
      EXPECT_EQ(b.samples, n);
      EXPECT_EQ(b.rays, std::uint64_t(n));
      if (k == 0 || k == n) {
        EXPECT_EQ(b.std_error, 0.0); // all equal: no spread, exactly
      }
    }
}

// point_along_first: the stratified sampler puts the i-th of N first coordinates in [i, i + 1) / N
// (every stratum once, for square and other N) and leaves the second uniform on [0, 1) (its mean
// within 5 standard errors of 1/2 over 4096 points); the independent sampler does not stratify.
TEST(reference_sampling, PointAlongFirstStratifiesTheFirstCoordinateOverAllSamples) {
  for (int n : {1, 7, 256, 4096}) {
    const SampleSet set(msm::reference::Sampler::stratified, n);
    Rng rng(11);
    double second = 0.0;
    for (int i = 0; i < n; ++i) {
      const glm::dvec2 p = set.point_along_first(i, rng);
      EXPECT_GE(p.x, double(i) / n) << i << " of " << n;
      EXPECT_LT(p.x, double(i + 1) / n) << i << " of " << n;
      EXPECT_GE(p.y, 0.0);
      EXPECT_LT(p.y, 1.0);
      second += p.y;
    }
    if (n == 4096) { EXPECT_NEAR(second / n, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n)); }
  }
  const SampleSet independent(msm::reference::Sampler::independent, 64);
  Rng rng(11);
  int outside = 0;
  for (int i = 0; i < 64; ++i) {
    const double x = independent.point_along_first(i, rng).x;
    if (x < i / 64.0 || x >= (i + 1) / 64.0) ++outside;
  }
  EXPECT_GT(outside, 32); // 63 of 64 expected outside their stratum
}

} // namespace
