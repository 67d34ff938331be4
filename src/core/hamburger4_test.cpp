// Hamburger and Hausdorff 4MSM and the three-moment reconstruction (single precision, shared with
// GLSL) against the double-precision oracles: JCGT Algorithm 1 and the 2015 LP.
#include "msm/msm.h"
#include "msm/oracle/lp_oracle.h"
#include "msm/oracle/moment_oracle.h"
#include "oracle_range.h"
#include "test_distributions.h"

#include "msm/test/figures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace {

using namespace msm;

using test::ErrorStats;

std::vector<double> as_double_moments(vec4 b) { return {1.0, b[0], b[1], b[2], b[3]}; }

// A random fragment depth: anywhere, or close to one of the depths (where bounds change fastest).
float random_fragment_depth(std::mt19937_64& rng, const test::Distribution& d, float lo, float hi) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  if (unit(rng) < 0.5f) return lo - 0.1f * (hi - lo) + 1.2f * (hi - lo) * unit(rng);
  return float(d.z[size_t(unit(rng) * d.z.size()) % d.z.size()]) + (unit(rng) - 0.5f) * 0.02f * (hi - lo);
}

// Agreement with JCGT Algorithm 1 on the same (float, biased) moment vector: what remains is the
// float arithmetic of the LDLᵀ solve, the quadratic and the closed forms, and the pivot floor of
// hamburger4.h (D2 raised to one rounding of b4, the light side of vectors whose D2 the rounding
// hid). Near-singular Hankel matrices (one or two depths: D2 ~ α) with zf within ~1e-3 of a depth
// are ill-conditioned in single precision; the pivots use fused multiply-adds, which cut this error
// 100-fold. Tolerance rule (oracle_range.h): the reference is the range of Algorithm 1 over the
// vector moved by up to 4 ulps per component, so that a failure is the algorithm's, not the
// input's rounding (computed where the result differs from the input vector's own bound by more
// than 1e-6). Measured: distance to that range 0 (lower), max 3.4e-5 ([-1,1]) and 6.5e-5 ([0,1])
// (upper); plain difference from the input vector's own bound p99 1.7e-5 ([-1,1]), 7.6e-5
// ([0,1]), max 2.9e-3 and 8.0e-2 (the floor, inside the range). Bounds: distance 1e-5 (lower), 5e-4 (upper:
// w0 = 1 / (c0 + zf (c1 + zf c2)) amplifies the rounding of c); plain difference p99 2e-4.
void check_against_moment_oracle(bool signed_depth, int representation) {
  std::mt19937_64 rng(signed_depth ? 1 : 2);
  float lo = signed_depth ? -1.0f : 0.0f, hi = 1.0f;
  MomentBias4 bias = msm_moment_bias(representation);
  ErrorStats lower_err, upper_err, lower_plain;
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_distribution(rng, lo, hi);
    vec4 b = msm_apply_bias(test::moments4f(d), bias);
    float zf = random_fragment_depth(rng, d, lo, hi);
    oracle::MomentBounds ref = oracle::moment_bounds(as_double_moments(b), zf);
    if (!ref.ok) continue; // the float rounding left the moment space; edges_test checks those
    vec2 bounds = msm_hamburger4_bounds(b, zf);
    ASSERT_TRUE(std::isfinite(bounds.x) && std::isfinite(bounds.y));
    lower_plain.add(bounds.x - ref.lower);
    ++checked;
    if (std::abs(bounds.x - ref.lower) <= 1e-6 && std::abs(bounds.y - std::min(ref.upper, 1.0)) <= 1e-6) {
      lower_err.add(0.0), upper_err.add(0.0); // inside the range: the range is only needed beyond that
      continue;
    }
    test::BoundRange range = test::hamburger_range({b[0], b[1], b[2], b[3]}, zf, 4, 8, rng);
    lower_err.add(range.lower_distance(bounds.x));
    upper_err.add(range.upper_distance(bounds.y));
  }
  EXPECT_GT(checked, 19000);
  std::printf("[hamburger4 vs JCGT Alg. 1, %s depth] distance to the range over 4 ulps: lower p99 %.2e max %.2e, "
              "upper p99 %.2e max %.2e; plain difference from the input's bound: p50 %.2e p99 %.2e max %.2e\n",
              signed_depth ? "[-1,1]" : "[0,1]", lower_err.quantile(0.99), lower_err.max(), upper_err.quantile(0.99),
              upper_err.max(), lower_plain.quantile(0.5), lower_plain.quantile(0.99), lower_plain.max());
  EXPECT_LT(lower_err.max(), 1e-5);
  EXPECT_LT(upper_err.max(), 5e-4);
  EXPECT_LT(lower_plain.quantile(0.99), 2e-4);
  const std::string key = signed_depth ? "math.hamburger4_signed_vs_alg1." : "math.hamburger4_unit_vs_alg1.";
  const std::string what =
      signed_depth ? "Hamburger 4MSM, [-1,1] depth, vs JCGT Alg. 1: " : "Hamburger 4MSM, [0,1] depth, vs JCGT Alg. 1: ";
  test::record_figure(key + "lower_range_distance_max", lower_err.max(),
                      {.below = 1e-5, .meaning = what + "lower bound's distance to the range over 4 ulps, max"});
  test::record_figure(key + "upper_range_distance_max", upper_err.max(),
                      {.below = 5e-4, .meaning = what + "upper bound's distance to the range over 4 ulps, max"});
  test::record_figure(key + "lower_error_p99", lower_plain.quantile(0.99),
                      {.below = 2e-4, .meaning = what + "lower bound's error, p99"});
}

TEST(Hamburger4, EqualsJcgtAlgorithm1UnitDepth) { check_against_moment_oracle(false, MSM_REP_UNIT_FLOAT); }
TEST(Hamburger4, EqualsJcgtAlgorithm1SignedDepth) { check_against_moment_oracle(true, MSM_REP_SIGNED_FLOAT); }

// Lower <= true CDF <= upper. Biasing replaces Z by (1-α) Z + α Z*, which moves the CDF by at
// most α, and the float arithmetic adds the error measured above: slack 2e-3 for 99.9% of cases.
TEST(Hamburger4, BoundsBracketTheTrueCdf) {
  std::mt19937_64 rng(3);
  int violations = 0, total = 20000;
  for (int i = 0; i < total; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    vec4 b = msm_apply_bias(test::moments4f(d), msm_moment_bias(MSM_REP_SIGNED_FLOAT));
    float zf = random_fragment_depth(rng, d, -1.0f, 1.0f);
    vec2 bounds = msm_hamburger4_bounds(b, zf);
    if (bounds.x > test::cdf_less(d, zf) + 2e-3 || bounds.y < test::cdf_less_equal(d, zf) - 2e-3) ++violations;
  }
  EXPECT_LE(violations, total / 1000);
}

// 2015 Proposition 4: with at most m/2 = 2 depths in the kernel the moments determine the
// distribution and the lower bound is the exact answer, away from the depths themselves. The
// float bias α = 3e-7 adds a third, remote depth; its effect grows as the two depths approach
// each other (that is the short-range light leaking of JCGT Fig. 4): measured up to 0.2 for
// depths 0.04 apart), and it smears each step of the CDF over a few hundredths beyond each depth
// (where a depth bias puts receivers anyway). For depths >= 0.2 apart, weights >= 5% and
// fragments >= 0.05 away from every depth, the remaining bias error measured 1.7e-4 (p99) and
// 6.8e-3 (max, depths 0.2 apart with one weight near 5%): bounds 5e-4 and 1e-2.
TEST(Hamburger4, ExactForUpToTwoDepths) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  ErrorStats err;
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_diracs(rng, 1 + i % 2, -1.0, 1.0);
    if (d.z.size() == 2 && (std::abs(d.z[0] - d.z[1]) < 0.2 || std::min(d.w[0], d.w[1]) < 0.05)) continue;
    float zf = -1.0f + 2.0f * unit(rng);
    bool near_atom = false;
    for (double z : d.z) near_atom |= std::abs(z - zf) < 0.05;
    if (near_atom) continue;
    vec4 b = msm_apply_bias(test::moments4f(d), msm_moment_bias(MSM_REP_SIGNED_FLOAT));
    err.add(msm_hamburger4_lower(b, zf) - test::cdf_less(d, zf));
  }
  err.expect_below("hamburger4 exactness, <= 2 depths", 8001, 0.99, 5e-4, 1e-2);
  const char* what = "Hamburger 4MSM lower vs the true CDF, 1-2 depths >= 0.2 apart, 0.05 away from them: ";
  test::record_figure("math.hamburger4_two_depths_exact.error_p99", err.quantile(0.99),
                      {.below = 5e-4, .meaning = std::string(what) + "error, p99"});
  test::record_figure("math.hamburger4_two_depths_exact.error_max", err.max(),
                      {.below = 1e-2, .meaning = std::string(what) + "error, max"});
}

// The canonical distribution reproduces b0..b4 (it is what the blocker search averages).
TEST(Hamburger4, CanonicalDistributionHasTheInputMoments) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 2000; ++i) {
    test::Distribution d = test::random_continuous(rng, -1.0, 1.0);
    vec4 b = msm_apply_bias(test::moments4f(d), msm_moment_bias(MSM_REP_SIGNED_FLOAT));
    float zf = float(d.z[0]) - 0.3f;
    oracle::MomentBounds ref = oracle::moment_bounds(as_double_moments(b), zf);
    if (!ref.ok) continue;
    Canonical4 c = msm_hamburger4_canonical(b, zf);
    for (int l = 0; l < 3; ++l) {
      EXPECT_NEAR(c.z[l], ref.support[l], 2e-3 * (1.0 + std::abs(ref.support[l])));
      EXPECT_NEAR(c.w[l], ref.weights[l], 2e-3);
    }
  }
}

// The LP of the 2015 paper on a grid, solved exactly (GLPK's rational re-solve): minimizing over
// distributions on the grid only, its optimum is >= the sharp bound over the whole domain and
// approaches it as the grid resolves the optimal atoms. So: never float > LP beyond float error
// (1e-3), and equality up to the grid: measured max 2.1e-5 (Hamburger, wide grid) and 4.7e-5
// (Hausdorff, 1e-3 spacing on [0,1]; 2.0e-3 before its four-atom branch was rewritten); bounds p90 1e-4, max 5e-3. Few cases: an exact LP takes
// 0.2-0.7 s.
void check_against_lp(const std::vector<double>& grid, bool hausdorff, int cases, uint64_t seed) {
  std::mt19937_64 rng(seed);
  oracle::Basis basis = oracle::power_basis(4);
  float lo = hausdorff ? 0.0f : -1.0f;
  ErrorStats err;
  int four_atom_cases = 0;
  for (int i = 0; i < cases; ++i) {
    test::Distribution d = test::random_distribution(rng, lo, 1.0);
    vec4 b = msm_apply_bias(test::moments4f(d), msm_moment_bias(hausdorff ? MSM_REP_UNIT_FLOAT : MSM_REP_SIGNED_FLOAT));
    float zf = random_fragment_depth(rng, d, lo, 1.0f);
    if (hausdorff) zf = std::clamp(zf, 0.0f, 1.0f);
    std::vector<double> bd = {b[0], b[1], b[2], b[3]};
    oracle::LpOptions exact;
    exact.exact = true; // rational re-solve: the simplex's 1e-7 feasibility tolerance admits
                        // wrong distributions when B is nearly singular (measured: 0.1 off)
    oracle::LpBounds lp = oracle::lp_bounds(grid, basis, bd, zf, exact);
    if (!lp.feasible) continue;
    Hamburger4Roots r = msm_hamburger4_roots(b, zf);
    four_atom_cases += (r.z2 < 0.0f || r.z3 > 1.0f);
    float bound = hausdorff ? msm_hausdorff4_lower(b, zf, 0.0f, 1.0f) : msm_hamburger4_lower(b, zf);
    EXPECT_LE(bound - lp.lower, 1e-3) << "zf " << zf;
    err.add(bound - lp.lower);
  }
  std::printf("[%s vs LP] n %zu p90 %.2e max %.2e (Hausdorff four-atom branch: %d)\n",
              hausdorff ? "hausdorff4 on [0,1]" : "hamburger4 on a wide grid", err.errors.size(), err.quantile(0.9),
              err.max(), four_atom_cases);
  EXPECT_GT(err.errors.size(), size_t(cases * 8 / 10));
  EXPECT_LT(err.quantile(0.9), 1e-4);
  EXPECT_LT(err.max(), 5e-3);
  const std::string key = hausdorff ? "math.hausdorff4_vs_lp." : "math.hamburger4_vs_lp.";
  const std::string what = hausdorff ? "Hausdorff 4MSM on [0,1] vs the 2015 LP on [0,1], exact: "
                                     : "Hamburger 4MSM vs the 2015 LP on a wide grid, exact: ";
  test::record_figure(key + "error_p90", err.quantile(0.9), {.below = 1e-4, .meaning = what + "error, p90"});
  test::record_figure(key + "error_max", err.max(), {.below = 5e-3, .meaning = what + "error, max"});
  if (hausdorff) {
    EXPECT_GT(four_atom_cases, 4); // the branch that differs from Hamburger is exercised
  }
}

TEST(Hamburger4, EqualsTheLinearProgramOnAWideGrid) {
  check_against_lp(oracle::wide_grid(-1.0, 1.0, 2001), false, 30, 6);
}

// Hausdorff 4MSM is the LP on [0,1] itself (uniform grid, 1001 points plus zf).
TEST(Hausdorff4, EqualsTheLinearProgramOnTheUnitInterval) {
  check_against_lp(oracle::uniform_grid(0.0, 1.0, 1001), true, 60, 7);
}

// Knowing the interval can only sharpen: Hausdorff >= Hamburger (up to float noise).
TEST(Hausdorff4, IsNeverBelowHamburger) {
  std::mt19937_64 rng(8);
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_distribution(rng, 0.0, 1.0);
    vec4 b = msm_apply_bias(test::moments4f(d), msm_moment_bias(MSM_REP_UNIT_FLOAT));
    float zf = std::clamp(random_fragment_depth(rng, d, 0.0f, 1.0f), 0.0f, 1.0f);
    EXPECT_GE(msm_hausdorff4_lower(b, zf, 0.0f, 1.0f), msm_hamburger4_lower(b, zf) - 2e-3f);
  }
}

// JCGT Algorithm 2: two depths from three moments reproduce b1..b3 exactly (in float: 1e-4
// relative) and recover any two-Dirac distribution.
TEST(ThreeMoments, RecoversTwoDiracsAndMatchesMoments) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 10000; ++i) {
    float z1 = -1.0f + 2.0f * unit(rng), z2 = -1.0f + 2.0f * unit(rng), w2 = 0.05f + 0.9f * unit(rng);
    if (std::abs(z1 - z2) < 0.05f) continue;
    vec4 b = (1.0f - w2) * msm_moments4(z1) + w2 * msm_moments4(z2);
    TwoDepths t = msm_two_depths_from_three_moments(vec3(b[0], b[1], b[2]));
    EXPECT_NEAR(t.z.x, std::min(z1, z2), 2e-3f);
    EXPECT_NEAR(t.z.y, std::max(z1, z2), 2e-3f);
    EXPECT_NEAR(t.w.y, z1 < z2 ? w2 : 1.0f - w2, 2e-3f);
  }
  for (int i = 0; i < 10000; ++i) {
    test::Distribution d = test::random_continuous(rng, -1.0, 1.0);
    vec4 b = test::moments4f(d);
    TwoDepths t = msm_two_depths_from_three_moments(vec3(b[0], b[1], b[2]));
    for (int j = 1; j <= 3; ++j) {
      float m = t.w.x * std::pow(t.z.x, float(j)) + t.w.y * std::pow(t.z.y, float(j));
      EXPECT_NEAR(m, b[j - 1], 1e-4f);
    }
  }
  // Zero variance: a single depth comes back as δ(b1).
  TwoDepths single = msm_two_depths_from_three_moments(vec3(0.25f, 0.0625f, 0.015625f));
  EXPECT_EQ(single.z.x, 0.25f);
  EXPECT_EQ(single.w.x, 1.0f);
}

} // namespace
