// Non-linearly quantized moment shadow maps (include/msm/nonlinear.h, HPG 2017 §3) against the
// double-precision moment oracle (JCGT Algorithm 1), against Hamburger 4MSM in float, and against
// the figures the paper states. Every tolerance says where it comes from; measured values are
// printed (grep "[nonlinear").
#include "msm/filter.h"
#include "msm/local_light.h"
#include "msm/msm.h"
#include "msm/nonlinear.h"
#include "msm/oracle/moment_oracle.h"
#include "test_distributions.h"

#include "msm/test/figures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace {

using namespace msm;

struct ErrorStats {
  std::vector<double> errors;
  double sum = 0.0;
  void add(double e) {
    errors.push_back(std::abs(e));
    sum += std::abs(e);
  }
  double mean() const { return errors.empty() ? 0.0 : sum / double(errors.size()); }
  double quantile(double q) {
    std::sort(errors.begin(), errors.end());
    return errors.empty() ? 0.0 : errors[size_t(q * double(errors.size() - 1))];
  }
  double max() { return quantile(1.0); }
};

// Positive part of signed differences: how far a value exceeds a reference.
struct Excess {
  double max = 0.0;
  long count = 0, over = 0;
  void add(double e, double tolerance) {
    max = std::max(max, e);
    ++count;
    if (e > tolerance) ++over;
  }
};

MomentBias4 float_bias() { return msm_moment_bias(MSM_REP_SIGNED_FLOAT); }

// Φ of a distribution as a shadow map would compute it: float moments, float bias, float Φ.
NonLinearMoments nl_of(const test::Distribution& d) {
  return msm_nl_from_moments(msm_apply_bias(test::moments4f(d), float_bias()));
}

// Eq. (4) in double, from the float values of m: the moments the NL representation stands for.
std::vector<double> moments_from_double(const NonLinearMoments& m) {
  double v2 = m.v2, v1 = 1.0 - v2, y1 = m.y1, y2 = m.y2;
  return {1.0, v1 * y1 + v2 * y2, v1 * y1 * y1 + v2 * y2 * y2, v1 * y1 * y1 * y1 + v2 * y2 * y2 * y2,
          v1 * y1 * y1 * y1 * y1 + v2 * y2 * y2 * y2 * y2 + double(m.xi4)};
}

// What msm_nl_shadow sees: the clamps of Algorithm 3's preamble applied to the input (the
// unquantized Φ output has ξ4 >= 0, down to 0; the floor MSM_NL_XI4_SHADING_MIN is 1e-12).
NonLinearMoments clamped(NonLinearMoments m) {
  m.y2 = std::max(m.y2, m.y1 + MSM_NL_TOLERANCE);
  m.v2 = std::clamp(m.v2, MSM_NL_TOLERANCE, 1.0f - MSM_NL_TOLERANCE);
  m.xi4 = std::max(m.xi4, MSM_NL_XI4_SHADING_MIN);
  return m;
}

// HPG Algorithm 3 literally (the paper's q0, q1 and root formula) in double, with the erratum
// (printed = false) or with w_l as printed, ξ'4 multiplied (printed = true).
double algorithm3_double(double y1, double y2, double v2, double xi4, double zf, bool printed) {
  if (zf <= y1) return 0.0;
  double zf1 = (zf - y1) / (y2 - y1);
  double xi = xi4 / std::pow(y2 - y1, 4.0);
  double zl = zf1;
  bool between = zf <= y2;
  if (between) {
    double q0 = -xi / ((1.0 - v2) * zf1);
    double q1 = -q0 * (v2 - zf1) / (v2 - v2 * zf1) - 1.0;
    zl = -0.5 * q1 - std::sqrt(0.25 * q1 * q1 - q0);
  }
  double u = 1.0 - zl;
  double last = printed ? xi * u * u * zl * zl : u * u * zl * zl / xi;
  double wl = 1.0 / (u * u / (1.0 - v2) + zl * zl / v2 + last);
  return between ? wl : 1.0 - wl;
}

// The Eq. (4) moments with ξ4 > 0 are positive definite in exact arithmetic, however close to
// singular (ξ4 down to 1e-12, y2 - y1 down to 1e-6 after the clamps): never let the oracle call
// them singular.
oracle::MomentOptions exact_options() {
  oracle::MomentOptions options;
  options.singular_tolerance = 0.0;
  return options;
}

// A fragment depth: anywhere in [-1.2, 1.2], or within 0.02 of y1 or y2 (where the bound is
// steepest and the root formula is least well conditioned).
float random_fragment_depth(std::mt19937_64& rng, const NonLinearMoments& m) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  float u = unit(rng);
  if (u < 0.4f) return -1.2f + 2.4f * unit(rng);
  float y = u < 0.7f ? m.y1 : m.y2;
  return y + 0.04f * (unit(rng) - 0.5f);
}

// ---------------------------------------------------------------------------------------------
// Φ (Algorithm 2) and Eq. (4)
// ---------------------------------------------------------------------------------------------

// Eq. (4) after Φ gives b back. Both are float; the error comes from the quadratic's roots,
// whose error grows as σ² -> 0, but Eq. (4) re-forms b1..b3 from the roots consistently, and
// ξ4 soaks up the error of b4. Tolerance: 2e-6 absolute per component = ~16 ulp of 1 (the
// moments of [-1,1] depths are at most 1 in magnitude, so absolute error is the relative error
// with respect to the scale of the data); measured max is printed.
TEST(NonLinear, EquationFourInvertsPhi) {
  std::mt19937_64 rng(11);
  ErrorStats err[4];
  for (int i = 0; i < 100000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    vec4 b = msm_apply_bias(test::moments4f(d), float_bias());
    vec4 r = msm_nl_moments_from(msm_nl_from_moments(b));
    for (int j = 0; j < 4; ++j) err[j].add(r[j] - b[j]);
  }
  std::printf("[nonlinear Eq.(4) o Phi, float] max abs error b1 %.2e b2 %.2e b3 %.2e b4 %.2e\n", err[0].max(),
              err[1].max(), err[2].max(), err[3].max());
  for (int j = 0; j < 4; ++j) EXPECT_LT(err[j].max(), 2e-6) << "b" << j + 1;
}

// Algorithm 2 in double (for the float moment vectors that the float path sees).
struct PhiDouble {
  double y1, y2, v2, xi4, sigma2;
};
PhiDouble phi_double(double b1, double b2, double b3, double b4) {
  double q2 = b2 - b1 * b1, q1 = b1 * b2 - b3, q0 = -b1 * q1 - b2 * q2;
  double p = q1 / q2, q = q0 / q2, r = std::sqrt(std::max(0.25 * p * p - q, 0.0));
  double y1 = -0.5 * p - r, y2 = -0.5 * p + r, L21 = (b3 - b1 * b2) / q2;
  return {y1, y2, (b1 - y1) / (y2 - y1), b4 - b2 * b2 - L21 * L21 * q2, q2};
}

// y1 <= y2 in [-1,1], v2 in [0,1] (HPG §3.1, supplementary), 0 <= ξ4 <= 0.25 (HPG §3.2, §3.3)
// on random distributions on [-1,1] through the float path: exactly, since Φ clamps. The clamps
// only absorb rounding, which this test measures with Algorithm 2 in double on the same float
// (biased) moments:
//  - exact arithmetic on the float moments keeps y in [-1,1] (to 1e-6) and ξ4 >= -1.2e-7 (one
//    ulp of 1: the float rounding of the moment vector, which the bias α = 3e-7 only just beats);
//  - the float Φ's depths differ from those by ~ulp / σ² (ill-conditioned roots), weighted by
//    the depth's weight <= 1e-3 (a far-off depth from a tiny σ² carries weight ~α; where weights
//    are large, σ² is not tiny). Measured values printed.
TEST(NonLinear, PhiRangesOnRandomDistributions) {
  std::mt19937_64 rng(12);
  float min_xi4 = 1.0f, max_xi4 = 0.0f;
  double min_xi4_double = 1.0, min_y_double = 1.0, max_y_double = -1.0, max_weighted_dy = 0.0;
  for (int i = 0; i < 200000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    vec4 b = msm_apply_bias(test::moments4f(d), float_bias());
    NonLinearMoments m = msm_nl_from_moments(b);
    ASSERT_LE(-1.0f, m.y1);
    ASSERT_LE(m.y1, m.y2);
    ASSERT_LE(m.y2, 1.0f);
    ASSERT_GE(m.v2, 0.0f);
    ASSERT_LE(m.v2, 1.0f);
    min_xi4 = std::min(min_xi4, m.xi4);
    max_xi4 = std::max(max_xi4, m.xi4);
    PhiDouble p = phi_double(b[0], b[1], b[2], b[3]);
    min_xi4_double = std::min(min_xi4_double, p.xi4);
    min_y_double = std::min(min_y_double, p.y1);
    max_y_double = std::max(max_y_double, p.y2);
    max_weighted_dy = std::max({max_weighted_dy, (1.0 - p.v2) * std::abs(m.y1 - p.y1), p.v2 * std::abs(m.y2 - p.y2)});
  }
  std::printf("[nonlinear Phi ranges] float: xi4 in [%.3e, %.3e]; double on the float moments: xi4 >= %.3e, "
              "y in [%.9f, %.9f]; max weight * |y_float - y_double| %.2e\n",
              min_xi4, max_xi4, min_xi4_double, min_y_double, max_y_double, max_weighted_dy);
  EXPECT_GE(min_xi4, 0.0f);
  EXPECT_LE(max_xi4, MSM_NL_XI4_MAX);
  EXPECT_GE(min_xi4_double, -1.2e-7);
  EXPECT_GE(min_y_double, -1.0 - 1e-6);
  EXPECT_LE(max_y_double, 1.0 + 1e-6);
  EXPECT_LT(max_weighted_dy, 1e-3);
}

// Two Diracs are recovered: Φ of (1 - v) δ(y1) + v δ(y2) gives y1, y2, v back and ξ4 ≈ 0 before
// biasing (HPG §3.2: ξ4 = 0 if and only if det B = 0). The roots are ill conditioned: a rounding
// δb ≈ 1 ulp of the moments moves them by ~δb / σ²; measured max |error| · σ² is 2.3e-6 both for
// the float Φ and for Algorithm 2 in double on the float moments (so it is the float moments, not
// the arithmetic). Tolerance 4e-6 / σ² + 1e-6 for y and v (σ² = v (1 - v) (y2 - y1)² >= 1.2e-4
// here); ξ4 is a cancellation of O(1) terms: 1e-6.
TEST(NonLinear, PhiRecoversTwoDiracs) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int checked = 0;
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    float z1 = -1.0f + 2.0f * unit(rng), z2 = -1.0f + 2.0f * unit(rng), v = 0.05f + 0.9f * unit(rng);
    if (std::abs(z1 - z2) < 0.05f) continue;
    float lo = std::min(z1, z2), hi = std::max(z1, z2);
    vec4 b = (1.0f - v) * msm_moments4(lo) + v * msm_moments4(hi);
    NonLinearMoments m = msm_nl_from_moments(b);
    double sigma2 = double(v) * (1.0 - v) * (double(hi) - lo) * (double(hi) - lo);
    double tol = 4e-6 / sigma2 + 1e-6;
    EXPECT_NEAR(m.y1, lo, tol);
    EXPECT_NEAR(m.y2, hi, tol);
    EXPECT_NEAR(m.v2, v, tol);
    EXPECT_NEAR(m.xi4, 0.0f, 1e-6f);
    worst = std::max({worst, std::abs(m.y1 - lo) * sigma2, std::abs(m.y2 - hi) * sigma2, std::abs(m.v2 - v) * sigma2});
    ++checked;
  }
  std::printf("[nonlinear Phi two Diracs] max |error| * sigma^2 = %.2e\n", worst);
  EXPECT_GT(checked, 18000);
}

// ξ4 in double from b1..b4 (Algorithm 2, steps 1, 6, 7).
double xi4_double(double b1, double b2, double b3, double b4) {
  double sigma2 = b2 - b1 * b1;
  double L21 = (b3 - b1 * b2) / sigma2;
  return b4 - b2 * b2 - L21 * L21 * sigma2;
}

// HPG §3.2 (ERRATA.md): Z = ½δ(0.915) + ½δ(1) has ξ4 = 0 before and ≈ 2.8e-4 after the 64-bit
// bias b* = (1, 0, 0.628, 0, 0.628), α = 6e-5. Double: ξ4 = 0 to 1e-15 (O(1) terms, double
// rounding); after biasing within [2.75e-4, 2.85e-4] (the paper gives two digits). Float: the
// cancellation of O(1) terms leaves up to ~1e-6 before biasing, and ±1% after.
TEST(NonLinear, HpgSection32Figure) {
  const double alpha = MSM_ALPHA_SIGNED_16BIT;
  const double bstar[4] = {0.0, MSM_BSTAR_SIGNED_16BIT[1], 0.0, MSM_BSTAR_SIGNED_16BIT[3]};
  EXPECT_EQ(alpha, double(6e-5f));
  EXPECT_NEAR(bstar[1], 0.628, 1e-7);
  double b[4], bb[4];
  for (int j = 0; j < 4; ++j) {
    b[j] = 0.5 * std::pow(0.915, j + 1) + 0.5;
    bb[j] = (1.0 - alpha) * b[j] + alpha * bstar[j];
  }
  double before = xi4_double(b[0], b[1], b[2], b[3]);
  double after = xi4_double(bb[0], bb[1], bb[2], bb[3]);
  std::printf("[nonlinear HPG 3.2 figure] double: xi4 before %.3e after %.4e\n", before, after);
  EXPECT_NEAR(before, 0.0, 1e-15);
  EXPECT_GE(after, 2.75e-4);
  EXPECT_LE(after, 2.85e-4);

  vec4 bf = 0.5f * msm_moments4(0.915f) + 0.5f * msm_moments4(1.0f);
  NonLinearMoments before_f = msm_nl_from_moments(bf);
  NonLinearMoments after_f = msm_nl_from_moments(msm_apply_bias(bf, msm_moment_bias(MSM_REP_SIGNED_THETA4)));
  std::printf("[nonlinear HPG 3.2 figure] float: xi4 before %.3e after %.4e\n", before_f.xi4, after_f.xi4);
  EXPECT_NEAR(before_f.xi4, 0.0f, 1e-6f);
  EXPECT_NEAR(after_f.xi4, after, 0.01 * after);
  EXPECT_NEAR(before_f.y1, 0.915f, 1e-4f);
  EXPECT_NEAR(before_f.y2, 1.0f, 1e-4f);
  EXPECT_NEAR(before_f.v2, 0.5f, 1e-4f);
}

// ... and it is the most extreme case: over all two-Dirac distributions on [-1,1] (a grid of
// depth pairs with step 1/200 and weights 0.05..0.95), the 64-bit bias raises ξ4 by at most
// 2.85e-4, and the maximum lies at {y1, y2} = {0.915, 1} or its mirror {-1, -0.915}, v2 = ½.
TEST(NonLinear, HpgSection32FigureIsTheWorstCase) {
  const double alpha = 6e-5, bs = 0.628;
  double worst = 0.0, arg_y1 = 0.0, arg_y2 = 0.0, arg_v = 0.0;
  for (int i = 0; i <= 400; ++i)
    for (int k = i + 1; k <= 400; ++k)
      for (int l = 1; l <= 19; ++l) {
        double y1 = -1.0 + i / 200.0, y2 = -1.0 + k / 200.0, v = l / 20.0, b[4];
        for (int j = 0; j < 4; ++j) {
          double m = (1.0 - v) * std::pow(y1, j + 1) + v * std::pow(y2, j + 1);
          b[j] = (1.0 - alpha) * m + alpha * (j % 2 == 1 ? bs : 0.0);
        }
        double xi = xi4_double(b[0], b[1], b[2], b[3]);
        if (xi > worst) worst = xi, arg_y1 = y1, arg_y2 = y2, arg_v = v;
      }
  std::printf("[nonlinear HPG 3.2 worst case] xi4 %.4e at y1 %.3f y2 %.3f v2 %.2f\n", worst, arg_y1, arg_y2, arg_v);
  EXPECT_LE(worst, 2.85e-4);
  EXPECT_GE(worst, 2.75e-4);
  EXPECT_NEAR(std::abs(arg_y1 + arg_y2), 1.915, 0.011);
  EXPECT_NEAR(arg_v, 0.5, 0.051);
}

// ---------------------------------------------------------------------------------------------
// Ψ4
// ---------------------------------------------------------------------------------------------

// The endpoints are exact: Ψ4 computes the same float expressions as its normalization
// constants. The constants agree with ln ln(1.2) and ln ln(2.5e6) in double to 1e-6 (the float
// product 1.2e-7f · 1e7f = 1.19999993 moves ln ln by 3e-7).
TEST(NonLinear, Psi4Endpoints) {
  EXPECT_EQ(msm_nl_psi4(MSM_NL_XI4_MIN), 0.0f);
  EXPECT_EQ(msm_nl_psi4(MSM_NL_XI4_MAX), 1.0f);
  EXPECT_EQ(msm_nl_psi4(0.0f), 0.0f);  // clamped below
  EXPECT_EQ(msm_nl_psi4(-1.0f), 0.0f); // negative ξ4 from rounding
  EXPECT_EQ(msm_nl_psi4(1.0f), 1.0f);  // above the bound for [-1,1]: saturated
  EXPECT_NEAR(MSM_NL_PSI4_LO, std::log(std::log(1.2)), 1e-6);
  EXPECT_NEAR(MSM_NL_PSI4_HI, std::log(std::log(2.5e6)), 1e-6);
  EXPECT_NEAR(msm_nl_psi4_inverse(0.0f), 1.2e-7, 1e-13);
  EXPECT_NEAR(msm_nl_psi4_inverse(1.0f), 0.25, 1e-6);
}

// Monotone (non-decreasing in float, strictly increasing at a spacing of 1e-4 in log ξ4), and
// the round trips: Ψ4⁻¹(Ψ4(ξ4)) = ξ4 to 2e-5 relative, because ξ4 = exp(exp(l)) / 1e7 amplifies
// the error of l by exp(l) <= ln(2.5e6) = 14.7 and the error of Ψ4 by (hi - lo) = 4.39 more:
// 14.7 · 4.39 · (a few ulp of 1 ≈ 2e-7) ≈ 1.3e-5. Ψ4(Ψ4⁻¹(u)) = u to 1e-6 absolute (a few ulp).
TEST(NonLinear, Psi4MonotoneAndInverse) {
  float prev = -1.0f, prev_spaced = -1.0f;
  ErrorStats rel, back;
  const int n = 200000;
  for (int i = 0; i <= n; ++i) {
    double lx = std::log(1e-9) + (std::log(0.3) - std::log(1e-9)) * i / n;
    float xi = float(std::exp(lx));
    float p = msm_nl_psi4(xi);
    ASSERT_GE(p, prev) << xi;
    prev = p;
    if (i % 50 == 0 && xi > 1.3e-7f && xi < 0.25f) {
      EXPECT_GT(p, prev_spaced) << xi;
      prev_spaced = p;
    }
    if (xi >= MSM_NL_XI4_MIN && xi <= MSM_NL_XI4_MAX) rel.add((msm_nl_psi4_inverse(p) - xi) / xi);
  }
  for (int i = 0; i <= n; ++i) {
    float u = float(i) / n;
    back.add(msm_nl_psi4(msm_nl_psi4_inverse(u)) - u);
  }
  std::printf("[nonlinear Psi4] inverse round trip: max rel error of xi4 %.2e, max abs error of Psi4 %.2e\n", rel.max(),
              back.max());
  EXPECT_LT(rel.max(), 2e-5);
  EXPECT_LT(back.max(), 1e-6);
}

// ---------------------------------------------------------------------------------------------
// Algorithm 3
// ---------------------------------------------------------------------------------------------

// Algorithm 3 with the erratum is Hamburger 4MSM of the Eq. (4) moments. Inputs: Φ of random
// biased float moments, the clamps of Algorithm 3 applied (so every method sees the same input).
//  (a) the literal Algorithm 3 in double vs the oracle (JCGT Alg. 1, long double) on the same
//      moments: only double rounding remains; the erratum (ERRATA.md) reports ~1e-13. Tolerance
//      1e-8: the canonical roots are ill conditioned near zf ≈ y_l for tiny ξ4.
//  (b) as printed (ξ'4 multiplied) in double vs the oracle: the error is large (measured max 0.93,
//      p99 0.37; ERRATA.md reports up to 0.66): max > 0.5 and p99 > 0.1. (a) measured max 5e-10.
//  (c) msm_nl_shadow (float) vs the oracle: float rounding only. Algorithm 3 never forms the
//      moments, so it does not suffer the cancellation that makes Hamburger in float lose digits
//      (hamburger4_test: 99% within 2e-3); the weights come from a well-scaled quadratic. Measured
//      p99 2e-7, max 1.7e-4 (zf within a few ulp of y_l with tiny ξ'4); tolerances
//      p99 <= 1e-5, max <= 2e-3.
//  (d) msm_nl_shadow vs msm_hamburger4_lower on the float Eq. (4) moments: the float rounding of
//      b4 (6e-8) is a relative perturbation of ξ4 up to 50% at ξ4 = 1.2e-7, so Hamburger in float
//      on those moments is the less accurate of the two (measured max 0.10 against the oracle);
//      compared where ξ4 >= 1e-5 (ξ4 then carries >= 7 bits in b4): measured p99 8e-6, max
//      2.1e-3; tolerances p99 <= 1e-4, max <= 0.02. Over all inputs, the mean error of Hamburger
//      float against the oracle is at least that of Algorithm 3 (c).
TEST(NonLinear, Algorithm3EqualsHamburger4) {
  std::mt19937_64 rng(21);
  ErrorStats exact_double, printed, nl_float, hb_float_conditioned, hb_float_all, hb_oracle;
  int skipped = 0; // the oracle fails (must not happen: B is positive definite by construction)
  for (int i = 0; i < 30000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    NonLinearMoments m = clamped(nl_of(d));
    std::vector<double> bd = moments_from_double(m);
    for (int k = 0; k < 2; ++k) {
      float zf = random_fragment_depth(rng, m);
      oracle::MomentBounds ref = oracle::moment_bounds(bd, zf, exact_options());
      if (!ref.ok) {
        ++skipped;
        continue;
      }
      exact_double.add(algorithm3_double(m.y1, m.y2, m.v2, m.xi4, zf, false) - ref.lower);
      printed.add(algorithm3_double(m.y1, m.y2, m.v2, m.xi4, zf, true) - ref.lower);
      float s = msm_nl_shadow(m, zf);
      ASSERT_TRUE(std::isfinite(s));
      nl_float.add(s - ref.lower);
      float h = msm_hamburger4_lower(msm_nl_moments_from(m), zf);
      hb_oracle.add(std::isfinite(h) ? h - ref.lower : 1.0);
      hb_float_all.add(std::isfinite(h) ? h - s : 1.0);
      if (m.xi4 >= 1e-5f) hb_float_conditioned.add(h - s);
    }
  }
  std::printf("[nonlinear Alg.3 (erratum), double, vs JCGT Alg.1] n %zu p99 %.2e max %.2e\n",
              exact_double.errors.size(), exact_double.quantile(0.99), exact_double.max());
  std::printf("[nonlinear Alg.3 as printed, double, vs JCGT Alg.1] p50 %.2e p99 %.2e max %.2e\n", printed.quantile(0.5),
              printed.quantile(0.99), printed.max());
  std::printf("[nonlinear msm_nl_shadow (float) vs JCGT Alg.1] mean %.2e p99 %.2e max %.2e\n", nl_float.mean(),
              nl_float.quantile(0.99), nl_float.max());
  std::printf("[nonlinear msm_hamburger4_lower (float, Eq.4 moments) vs JCGT Alg.1] mean %.2e p99 %.2e max %.2e\n",
              hb_oracle.mean(), hb_oracle.quantile(0.99), hb_oracle.max());
  std::printf("[nonlinear msm_nl_shadow vs msm_hamburger4_lower] xi4>=1e-5: n %zu p99 %.2e max %.2e; all: mean %.2e "
              "p99 %.2e max %.2e\n",
              hb_float_conditioned.errors.size(), hb_float_conditioned.quantile(0.99), hb_float_conditioned.max(),
              hb_float_all.mean(), hb_float_all.quantile(0.99), hb_float_all.max());
  EXPECT_EQ(skipped, 0);
  EXPECT_LT(exact_double.max(), 1e-8);
  EXPECT_GT(printed.max(), 0.5);
  EXPECT_GT(printed.quantile(0.99), 0.1);
  EXPECT_LT(nl_float.quantile(0.99), 1e-5);
  EXPECT_LT(nl_float.max(), 2e-3);
  test::record_figure(
      "math.nl_algorithm3_float_vs_alg1.error_p99", nl_float.quantile(0.99),
      {.below = 1e-5, .meaning = "non-linear Algorithm 3 (erratum), float, vs JCGT Alg. 1: error, p99"});
  test::record_figure(
      "math.nl_algorithm3_float_vs_alg1.error_max", nl_float.max(),
      {.below = 2e-3, .meaning = "non-linear Algorithm 3 (erratum), float, vs JCGT Alg. 1: error, max"});
  test::record_figure("math.nl_algorithm3_as_printed_vs_alg1.error_max", printed.max(),
                      {.above = 0.5,
                       .meaning = "non-linear Algorithm 3 as printed (ξ'4 multiplied), double, vs JCGT "
                                  "Alg. 1: error, max (the erratum is needed)"});
  EXPECT_GT(hb_float_conditioned.errors.size(), 5000u);
  EXPECT_LT(hb_float_conditioned.quantile(0.99), 1e-4);
  EXPECT_LT(hb_float_conditioned.max(), 0.02);
  EXPECT_GE(hb_oracle.mean(), nl_float.mean());
}

// At zf = y2 the paper's q1 has a pole (v2 - v2 z'f = 0): the literal formula is not finite there.
// msm_nl_shadow multiplies the polynomial by 1 - z'f and returns the limit zl = 0, w_l = 1 - v2:
// the canonical representation through zf = y2 has its third atom at infinity (2015 Prop. 3).
// The oracle handles that case itself; its weights must sum to 1. Tolerances as in (c) above.
TEST(NonLinear, Algorithm3AtTheSecondDepth) {
  std::mt19937_64 rng(22);
  ErrorStats err;
  int nan_literal = 0, oracle_broken_at_pole = 0;
  for (int i = 0; i < 5000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    NonLinearMoments m = clamped(nl_of(d));
    float zf = m.y2;
    std::vector<double> bd = moments_from_double(m);
    oracle::MomentBounds ref = oracle::moment_bounds(bd, zf, exact_options());
    ASSERT_TRUE(ref.ok) << ref.reason;
    double sum = 0.0;
    for (double w : ref.weights) sum += w;
    if (std::abs(sum - 1.0) > 1e-6) {
      ++oracle_broken_at_pole;
      continue;
    }
    float s = msm_nl_shadow(m, zf);
    ASSERT_TRUE(std::isfinite(s));
    err.add(s - ref.lower);
    if (!std::isfinite(algorithm3_double(m.y1, m.y2, m.v2, m.xi4, zf, false))) ++nan_literal;
  }
  std::printf("[nonlinear Alg.3 at zf = y2] n %zu p99 %.2e max %.2e (literal formula not finite in %d cases; oracle "
              "weights at zf = y2 not summing to 1 in %d)\n",
              err.errors.size(), err.quantile(0.99), err.max(), nan_literal, oracle_broken_at_pole);
  EXPECT_EQ(oracle_broken_at_pole, 0);
  EXPECT_GT(nan_literal, 4000); // the pole is real
  EXPECT_LT(err.quantile(0.99), 1e-5);
  EXPECT_LT(err.max(), 2e-3);
}

// ---------------------------------------------------------------------------------------------
// Packing
// ---------------------------------------------------------------------------------------------

// HPG Fig. 5: every ordered pair of 10-bit depth codes round-trips through the 19-bit fold, and
// the codes are distinct (a round trip is injective), all below 2^19.
TEST(NonLinear, TriangleFoldExhaustive) {
  long pairs = 0;
  for (uint t1 = 0; t1 <= MSM_NL32_DEPTH_MAX; ++t1)
    for (uint t2 = t1; t2 <= MSM_NL32_DEPTH_MAX; ++t2) {
      uint code = msm_nl_fold_depths(uvec2(t1, t2));
      ASSERT_LT(code, 1u << 19) << t1 << " " << t2;
      uvec2 back = msm_nl_unfold_depths(code);
      ASSERT_EQ(back.x, t1);
      ASSERT_EQ(back.y, t2);
      ++pairs;
    }
  EXPECT_EQ(pairs, 1023L * 1024L / 2L);
  // Unused codes decode to something in range too (d2 = 1023 or a folded pair out of the triangle).
  for (uint code = 0; code < (1u << 19); ++code) {
    uvec2 t = msm_nl_unfold_depths(code);
    ASSERT_LE(t.x, 1023u);
    ASSERT_LE(t.y, 1023u);
  }
}

// 10-bit depth codes: ỹ = floor(511.5 (y + 1)) in 0..1022, decoded at bin centers.
TEST(NonLinear, Depth10Bins) {
  EXPECT_EQ(msm_nl_depth10_encode(-1.0f), 0u);
  EXPECT_EQ(msm_nl_depth10_encode(1.0f), 1022u);
  EXPECT_EQ(msm_nl_depth10_encode(-2.0f), 0u);
  EXPECT_EQ(msm_nl_depth10_encode(2.0f), 1022u);
  for (uint t = 0; t <= MSM_NL32_DEPTH_MAX; ++t) {
    float y = msm_nl_depth10_decode(t);
    EXPECT_EQ(msm_nl_depth10_encode(y), t);
    EXPECT_NEAR(y, (t + 0.5) / 511.5 - 1.0, 1e-7);
  }
}

// Decoded Ψ4 is the least multiple of 1/63 that is >= Ψ4, for every float Ψ4 on a fine grid
// and at the level boundaries (where float rounding of Ψ4 · 63 could round down).
TEST(NonLinear, Psi4SixBitsRoundsUp) {
  for (int i = 0; i <= 1000000; ++i) {
    float p = float(i) / 1000000.0f;
    uint q = msm_nl_psi4_encode6(p);
    ASSERT_LE(q, 63u);
    ASSERT_GE(msm_nl_psi4_decode6(q), p) << p;
    if (q > 0) { ASSERT_LT(msm_nl_psi4_decode6(q - 1), p) << p; }
  }
  for (uint k = 0; k <= 63; ++k) {
    float level = msm_nl_psi4_decode6(k);
    for (float p : {std::nextafter(level, 0.0f), level, std::nextafter(level, 2.0f)}) {
      if (p < 0.0f || p > 1.0f) continue;
      EXPECT_GE(msm_nl_psi4_decode6(msm_nl_psi4_encode6(p)), p);
    }
    EXPECT_EQ(msm_nl_psi4_encode6(level), k);
  }
}

// Random and degenerate NL inputs for the packing tests.
struct NlCase {
  NonLinearMoments m;
};

std::vector<NonLinearMoments> degenerate_inputs() {
  std::vector<NonLinearMoments> out;
  std::vector<test::Distribution> ds;
  for (double z : {-1.0, -0.999, -0.5, 0.0, 0.3, 0.999, 1.0}) ds.push_back({{z}, {1.0}}); // one depth
  for (double z : {-1.0, 0.0, 0.7, 1.0}) ds.push_back({{z, z}, {0.3, 0.7}});              // two equal
  ds.push_back({{-1.0, 1.0}, {0.5, 0.5}});                                                // at ±1
  ds.push_back({{-1.0, 1.0}, {0.01, 0.99}});
  ds.push_back({{-1.0, 1.0}, {0.99, 0.01}});
  ds.push_back({{-1.0, -1.0, 1.0, 1.0}, {0.25, 0.25, 0.25, 0.25}}); // all depths clamped to ±1
  ds.push_back({{1.0, 1.0, 1.0}, {0.2, 0.3, 0.5}});
  ds.push_back({{-1.0, -1.0}, {0.2, 0.8}});
  ds.push_back({{0.915, 1.0}, {0.5, 0.5}});
  ds.push_back({{0.5, 0.5 + 1e-6}, {0.5, 0.5}});
  for (const test::Distribution& d : ds) {
    vec4 b = test::moments4f(d);
    out.push_back(msm_nl_from_moments(b));                               // unbiased
    out.push_back(msm_nl_from_moments(msm_apply_bias(b, float_bias()))); // biased
  }
  // Raw extremes a packer may see.
  for (float y1 : {-1.0f, -1.0000001f, 0.0f, 1.0f, 1.0000001f})
    for (float y2 : {-1.0f, 0.0f, 1.0f, 1.0000001f})
      for (float v2 : {0.0f, 1e-7f, 0.5f, 1.0f - 1e-7f, 1.0f})
        for (float xi4 : {-1e-7f, 0.0f, 1e-9f, 1.2e-7f, 0.25f, 0.3f})
          out.push_back(NonLinearMoments(std::min(y1, y2), std::max(y1, y2), v2, xi4));
  return out;
}

bool finite(const NonLinearMoments& m) {
  return std::isfinite(m.y1) && std::isfinite(m.y2) && std::isfinite(m.v2) && std::isfinite(m.xi4);
}

// ≥ 1e6 random inputs plus the degenerate ones, through 64 and 32 bits:
//  - decoded values finite and in range: -1 <= y1 <= y2 <= 1, v2 in [0,1], ξ4 in [1.2e-7, 0.25]
//    (to 1e-6 relative: Ψ4⁻¹ is a float exp(exp())), and the shading of the decoded values finite;
//  - 64 bits: each channel within half a 16-bit step (y: 1/65535 after the ×2; Ψ4: 0.5/65535 plus
//    1e-6 for the float evaluation of Ψ4 before and after);
//  - 32 bits: y within half a bin (1/1023, plus 1e-6), sqrt(v2) within half a 7-bit step, the
//    stored Ψ4 code >= Ψ4(ξ4) and less than one 6-bit step above it (the round up); the decoded
//    ξ4 then >= ξ4 up to Ψ4⁻¹'s 2e-5 relative float error.
TEST(NonLinear, PackUnpackRandomAndDegenerate) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<NonLinearMoments> inputs = degenerate_inputs();
  const size_t degenerate = inputs.size();
  for (int i = 0; i < 1000000; ++i) {
    float a = -1.0f + 2.0f * unit(rng), b = -1.0f + 2.0f * unit(rng);
    float xi4 = float(std::exp(std::log(1e-9) + (std::log(0.25) - std::log(1e-9)) * unit(rng)));
    inputs.push_back(NonLinearMoments(std::min(a, b), std::max(a, b), unit(rng), xi4));
  }
  double max_y64 = 0, max_v64 = 0, max_p64 = 0, max_y32 = 0, max_s32 = 0, max_p32_up = 0;
  double min_p32_up = 1.0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    const NonLinearMoments& m = inputs[i];
    float y1 = std::clamp(m.y1, -1.0f, 1.0f), y2 = std::clamp(m.y2, -1.0f, 1.0f);
    float v2 = std::clamp(m.v2, 0.0f, 1.0f), psi = msm_nl_psi4(m.xi4);
    for (int bits : {64, 32}) {
      NonLinearMoments q = bits == 64 ? msm_nl_quantize64(m) : msm_nl_quantize32(m);
      ASSERT_TRUE(finite(q)) << bits << " input " << i;
      ASSERT_LE(-1.0f, q.y1);
      ASSERT_LE(q.y1, q.y2);
      ASSERT_LE(q.y2, 1.0f);
      ASSERT_GE(q.v2, 0.0f);
      ASSERT_LE(q.v2, 1.0f);
      ASSERT_GE(q.xi4, MSM_NL_XI4_MIN * (1.0f - 1e-6f));
      ASSERT_LE(q.xi4, MSM_NL_XI4_MAX * (1.0f + 1e-6f));
      for (float zf : {-1.5f, -1.0f, q.y1, 0.5f * (q.y1 + q.y2), q.y2, 1.0f, 1.5f})
        ASSERT_TRUE(std::isfinite(msm_nl_shadow(q, zf))) << bits << " input " << i << " zf " << zf;
    }
    uvec2 p64 = msm_nl_pack64(m);
    vec4 u = msm_unpack_unorm16x4(p64);
    max_y64 = std::max({max_y64, std::abs(2.0 * u[0] - 1.0 - y1), std::abs(2.0 * u[1] - 1.0 - y2)});
    max_v64 = std::max(max_v64, std::abs(double(u[2]) - v2));
    max_p64 = std::max(max_p64, std::abs(double(u[3]) - psi));

    uint p32 = msm_nl_pack32(m);
    uvec2 t = msm_nl_unfold_depths(p32 & 0x7FFFFu);
    ASSERT_LE(t.x, t.y);
    ASSERT_LE(t.y, MSM_NL32_DEPTH_MAX);
    NonLinearMoments q = msm_nl_unpack32(p32);
    max_y32 = std::max({max_y32, std::abs(double(q.y1) - y1), std::abs(double(q.y2) - y2)});
    max_s32 = std::max(max_s32, std::abs(std::sqrt(double(q.v2)) - std::sqrt(double(v2))));
    float psi32 = msm_nl_psi4_decode6(p32 >> 26u);
    ASSERT_GE(psi32, psi) << "input " << i;
    max_p32_up = std::max(max_p32_up, double(psi32) - psi);
    min_p32_up = std::min(min_p32_up, double(psi32) - psi);
    ASSERT_GE(q.xi4, std::clamp(m.xi4, MSM_NL_XI4_MIN, MSM_NL_XI4_MAX) * (1.0f - 2e-5f)) << "input " << i;
  }
  std::printf("[nonlinear pack] %zu inputs (%zu degenerate). 64 bits: max |dy| %.2e |dv2| %.2e |dPsi4| %.2e. "
              "32 bits: max |dy| %.2e |d sqrt(v2)| %.2e, Psi4 rounded up by %.2e..%.2e\n",
              inputs.size(), degenerate, max_y64, max_v64, max_p64, max_y32, max_s32, min_p32_up, max_p32_up);
  EXPECT_LE(max_y64, 1.0 / 65535.0 + 1e-7);
  EXPECT_LE(max_v64, 0.5 / 65535.0 + 1e-7);
  EXPECT_LE(max_p64, 0.5 / 65535.0 + 1e-6);
  EXPECT_LE(max_y32, 1.0 / 1023.0 + 1e-6);
  EXPECT_LE(max_s32, 0.5 / 127.0 + 1e-6);
  EXPECT_LT(max_p32_up, 1.0 / 63.0);
}

// ---------------------------------------------------------------------------------------------
// Shadows from quantized NL moments
// ---------------------------------------------------------------------------------------------

// The lower bound decreases as ξ4 grows (HPG Fig. 3). That is why rounding Ψ4 up keeps a lower
// bound: with the depths and the weight left as they are, the shadow from the rounded-up ξ4 is
// never above the shadow from the true ξ4 (up to float noise 1e-5, measured on (c) above).
TEST(NonLinear, LargerXi4NeverRaisesTheShadow) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Excess excess;
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    NonLinearMoments m = nl_of(d);
    NonLinearMoments up = m;
    up.xi4 = msm_nl_psi4_inverse(msm_nl_psi4_decode6(msm_nl_psi4_encode6(msm_nl_psi4(m.xi4))));
    for (int k = 0; k < 8; ++k) {
      float zf = random_fragment_depth(rng, m);
      excess.add(msm_nl_shadow(up, zf) - msm_nl_shadow(m, zf), 1e-5);
    }
  }
  std::printf("[nonlinear rounded-up xi4] max excess of the shadow %.2e over %ld\n", excess.max, excess.count);
  EXPECT_EQ(excess.over, 0);
}

// Shadows of quantized NL moments on random distributions (biased float moments, then Φ) and
// random fragment depths (half uniform on [-1,1], half within 0.02 of y1 or y2):
//  - error against unquantized float MSM (msm_hamburger4_lower of the biased float moments),
//    mean and max, printed; also against JCGT Alg. 1 on the same float
//    moments (float MSM has its own rounding error, up to ~0.25 on these inputs, see above) and
//    against the true CDF (mostly the leaking every 4MSM has). Expected (HPG §5): NL64
//    indistinguishable from float MSM (mean <= 1e-4), NL32 adds banding only (mean <= 1e-2).
//    Inputs where float MSM is not finite are left out of its statistics (counted, printed).
//  - lower bound: ξ4 only grows in the quantization, so the decoded shadow can exceed the
//    unquantized one only because the depths and v2 moved. Near a steep step, a depth moved
//    across zf changes the shadow by up to the step height (measured, printed: up to ~0.94 at 32
//    bits), so the bound is checked with zf moved up by one depth step: the decoded shadow at zf
//    is compared with the unquantized shadow at zf + h, h = 2/65535 (64 bits) or 2/1023 (32 bits),
//    twice the largest depth rounding. What remains is the v2 rounding (64 bits: 7.6e-6; 32 bits:
//    |Δv2| <= 2 sqrt(v2) 0.5/127 <= 0.0079) plus float noise 2e-3 (Alg. 3 max error (c) ~2e-4,
//    with margin). 64 bits: no case over 2e-3 except texels with one depth of weight below one
//    16-bit step (min(v2, 1 - v2) < 1/65535, a single surface plus the bias): there v2 rounds to
//    0 or 1 (then clamped to 1e-6), which changes the variance of the texel by O(1) relative, and
//    with ξ4 ~ 1e-7 the steep step at the dominant depth moves (measured up to 0.11; bound 0.2).
//    32 bits: at most 0.1% of cases over 0.0099, none over 0.05 (the depth shift is not exactly a
//    shift of zf: y1 and y2 move independently, which rescales ξ'4).
TEST(NonLinear, QuantizedShadowErrors) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  ErrorStats nl_vs_msm, q64_vs_msm, q32_vs_msm, msm_vs_oracle, nl_vs_oracle, q64_vs_oracle, q32_vs_oracle;
  ErrorStats msm_vs_true, nl_vs_true, q64_vs_true, q32_vs_true;
  Excess ex64, ex32, ex64_shifted, ex32_shifted, ex64_shifted_tiny_weight;
  int msm_not_finite = 0;
  for (int i = 0; i < 25000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    vec4 b = msm_apply_bias(test::moments4f(d), float_bias());
    NonLinearMoments m = msm_nl_from_moments(b);
    NonLinearMoments m64 = msm_nl_quantize64(m), m32 = msm_nl_quantize32(m);
    for (int k = 0; k < 8; ++k) {
      float zf = k < 4 ? -1.0f + 2.0f * unit(rng) : random_fragment_depth(rng, m);
      float s = msm_nl_shadow(m, zf), s64 = msm_nl_shadow(m64, zf), s32 = msm_nl_shadow(m32, zf);
      double truth = test::cdf_less(d, zf);
      nl_vs_true.add(s - truth);
      q64_vs_true.add(s64 - truth);
      q32_vs_true.add(s32 - truth);
      float msm = msm_hamburger4_lower(b, zf);
      if (std::isfinite(msm)) {
        nl_vs_msm.add(s - msm);
        q64_vs_msm.add(s64 - msm);
        q32_vs_msm.add(s32 - msm);
        msm_vs_true.add(msm - truth);
      } else {
        ++msm_not_finite;
      }
      if (k % 2 == 0) {
        oracle::MomentBounds ref = oracle::moment_bounds(std::vector<double>{1.0, b[0], b[1], b[2], b[3]}, zf);
        if (ref.ok) {
          if (std::isfinite(msm)) msm_vs_oracle.add(msm - ref.lower);
          nl_vs_oracle.add(s - ref.lower);
          q64_vs_oracle.add(s64 - ref.lower);
          q32_vs_oracle.add(s32 - ref.lower);
        }
      }
      ex64.add(s64 - s, 1.0);
      ex32.add(s32 - s, 1.0);
      float e64 = s64 - msm_nl_shadow(m, zf + 2.0f / 65535.0f);
      if (std::min(m.v2, 1.0f - m.v2) < 1.0f / 65535.0f)
        ex64_shifted_tiny_weight.add(e64, 2e-3);
      else
        ex64_shifted.add(e64, 2e-3);
      ex32_shifted.add(s32 - msm_nl_shadow(m, zf + 2.0f / 1023.0f), 0.0079 + 2e-3);
    }
  }
  auto line = [](const char* name, ErrorStats& e) {
    std::printf("[nonlinear shadow error] %-38s n %7zu mean %.3e p99 %.3e max %.3e\n", name, e.errors.size(), e.mean(),
                e.quantile(0.99), e.max());
  };
  line("unquantized NL vs float MSM", nl_vs_msm);
  line("NL64 vs float MSM", q64_vs_msm);
  line("NL32 vs float MSM", q32_vs_msm);
  line("float MSM vs JCGT Alg.1 (same moments)", msm_vs_oracle);
  line("unquantized NL vs JCGT Alg.1", nl_vs_oracle);
  line("NL64 vs JCGT Alg.1", q64_vs_oracle);
  line("NL32 vs JCGT Alg.1", q32_vs_oracle);
  line("float MSM vs true CDF", msm_vs_true);
  line("unquantized NL vs true CDF", nl_vs_true);
  line("NL64 vs true CDF", q64_vs_true);
  line("NL32 vs true CDF", q32_vs_true);
  std::printf("[nonlinear shadow error] float MSM not finite in %d of %ld cases (left out above)\n", msm_not_finite,
              ex64.count);
  std::printf("[nonlinear lower bound] max excess over unquantized NL: NL64 %.3e, NL32 %.3e; with zf + one depth "
              "step: NL64 %.3e (%ld of %ld over 2e-3), NL64 with a depth of weight < 1/65535 %.3e (%ld of %ld over "
              "2e-3), NL32 %.3e (%ld of %ld over 0.0099)\n",
              ex64.max, ex32.max, ex64_shifted.max, ex64_shifted.over, ex64_shifted.count, ex64_shifted_tiny_weight.max,
              ex64_shifted_tiny_weight.over, ex64_shifted_tiny_weight.count, ex32_shifted.max, ex32_shifted.over,
              ex32_shifted.count);
  ::testing::Test::RecordProperty("nl64_vs_float_msm_mean", std::to_string(q64_vs_msm.mean()));
  ::testing::Test::RecordProperty("nl64_vs_float_msm_max", std::to_string(q64_vs_msm.max()));
  ::testing::Test::RecordProperty("nl32_vs_float_msm_mean", std::to_string(q32_vs_msm.mean()));
  ::testing::Test::RecordProperty("nl32_vs_float_msm_max", std::to_string(q32_vs_msm.max()));
  EXPECT_LT(msm_not_finite, int(ex64.count / 1000));
  EXPECT_LT(q64_vs_msm.mean(), 1e-4);
  EXPECT_LT(q32_vs_msm.mean(), 1e-2);
  EXPECT_EQ(ex64_shifted.over, 0);
  EXPECT_LT(ex64_shifted_tiny_weight.max, 0.2);
  EXPECT_LE(ex32_shifted.over, ex32_shifted.count / 1000);
  EXPECT_LT(ex32_shifted.max, 0.05);
}

// The bilinear lookup of the 64-bit map (msm_nl_bilinear: four decoded texels back to moments,
// interpolated, Φ again, as shading_nonlinear.glsl and the three.js package read it) on lit planes
// near a point light of range 20 m: the ground of one cube face (128² texels) 0.5, 1 and 2 m below
// the light ([-1,1] depths from -0.95 to -0.65), each texel's moments blurred by the 9-tap Gaussian
// (σ = 2.4 texels) and stored at 64 bits; 50000 receivers on the plane, at random within the face's
// inner texels, with the non-linear map's depth bias for local lights. Float MSM (msm-hamburger-128)
// of the same blurred moments, interpolated, has every one lit. A texel there is a nearly single
// depth with a second of weight ~1e-3 (the blur over the sloped plane) and ξ4 ~ 1e-7, whose
// moments about 0 are O(1) and cancel to those: interpolated and put through Φ in float, they
// lost them, and isolated receivers were shadowed (max 0.056, 0.50 and 0.64; 1, 93 and 10 of
// 50000 over 0.05). Taken about the interpolated mean: max 0 (bound 1e-3).
TEST(NonLinear, BilinearLookupOfLitPlanes) {
  const int n = 128, taps = 9;
  const float sigma = 2.4f, range = 20.0f;
  for (float below : {0.5f, 1.0f, 2.0f}) {
    // Texel (i, j)'s centre at face coordinates st = (i + 1/2) 2 / n - 1, the ground point below · (s, t).
    auto distance = [&](float i, float j) {
      float s = (i + 0.5f) * 2.0f / n - 1.0f, t = (j + 0.5f) * 2.0f / n - 1.0f;
      return below * std::sqrt(1.0f + s * s + t * t);
    };
    std::vector<vec4> moments(n * n), rows(n * n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        moments[j * n + i] = msm_moments4(msm_signed_depth(msm_local_light_depth(distance(float(i), float(j)), range)));
    auto blur = [&](const std::vector<vec4>& from, std::vector<vec4>& to, int di, int dj) {
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          vec4 sum(0.0f);
          for (int k = 0; k < taps; ++k) {
            int ii = std::clamp(i + (k - taps / 2) * di, 0, n - 1), jj = std::clamp(j + (k - taps / 2) * dj, 0, n - 1);
            sum += msm_gaussian_weight(k, taps, sigma) * from[jj * n + ii];
          }
          to[j * n + i] = sum;
        }
    };
    blur(moments, rows, 1, 0);
    blur(rows, moments, 0, 1);
    std::vector<NonLinearMoments> stored(n * n);
    for (int k = 0; k < n * n; ++k) stored[k] = msm_nl_quantize64(msm_nl_from_filtered(moments[k]));
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    float worst = 0.0f, worst_float = 0.0f;
    int over = 0;
    for (int k = 0; k < 50000; ++k) {
      float x = float(taps) + unit(rng) * float(n - 2 * taps), y = float(taps) + unit(rng) * float(n - 2 * taps);
      int i = int(std::floor(x)), j = int(std::floor(y));
      vec2 f(x - float(i), y - float(j));
      float zf =
          msm_signed_depth(msm_local_light_receiver_depth(distance(x, y), range, MSM_DEPTH_BIAS_NONLINEAR, 2.0f));
      NonLinearMoments m = msm_nl_bilinear(stored[j * n + i], stored[j * n + i + 1], stored[(j + 1) * n + i],
                                           stored[(j + 1) * n + i + 1], f);
      float shadow = msm_nl_shadow(m, zf);
      vec4 b = mix(mix(moments[j * n + i], moments[j * n + i + 1], f.x),
                   mix(moments[(j + 1) * n + i], moments[(j + 1) * n + i + 1], f.x), f.y);
      worst_float = std::max(worst_float, msm_hamburger4_lower(msm_apply_bias(b, float_bias()), zf));
      worst = std::max(worst, shadow);
      over += shadow > 0.05f ? 1 : 0;
    }
    std::printf("[nonlinear bilinear, a lit plane %.1f m below the light] max shadow %.4f (float MSM %.2e), %d of "
                "50000 over 0.05\n",
                below, worst, worst_float, over);
    ASSERT_LE(worst_float, 1e-3f) << below << " m below the light: the receivers are not all lit";
    EXPECT_LE(worst, 1e-3f) << below << " m below the light";
  }
}

} // namespace
