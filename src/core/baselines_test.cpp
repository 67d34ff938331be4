// The baselines of include/msm/baselines.h (VSM, ESM, EVSM, CSM, over-darkening; single
// precision, shared with GLSL) against double-precision references: the moment oracle (JCGT
// Algorithm 1), the LP oracle (2015 Algorithm 1) and closed forms computed here in double.
// Every tolerance is stated next to its check with the reason for its size; the measured values
// are printed so that they can be compared with the tolerances.
#include "msm/baselines.h"
#include "msm/oracle/lp_oracle.h"
#include "msm/oracle/moment_oracle.h"
#include "test_distributions.h"

#include "msm/test/figures.h"

#include <fmt/core.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

namespace {

using namespace msm;

using test::ErrorStats;

// E f(z) in double: the filtered texel before it is rounded to the storage format.
double expect(const test::Distribution& d, const std::function<double(double)>& f) {
  double s = 0.0;
  for (size_t i = 0; i < d.z.size(); ++i) s += d.w[i] * f(d.z[i]);
  return s;
}

// A random fragment depth: anywhere in a slightly widened range, or close to one of the depths
// (where the shadow changes fastest).
double random_fragment_depth(std::mt19937_64& rng, const test::Distribution& d, double lo, double hi) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  if (unit(rng) < 0.5) return lo - 0.1 * (hi - lo) + 1.2 * (hi - lo) * unit(rng);
  return d.z[size_t(unit(rng) * double(d.z.size())) % d.z.size()] + (unit(rng) - 0.5) * 0.02 * (hi - lo);
}

// A random distribution on [0,1] and a random fragment depth for it, clamped to [min_zf, 1].
struct UnitCase {
  test::Distribution d;
  double zf;
};
UnitCase unit_case(std::mt19937_64& rng, double min_zf = 0.0) {
  test::Distribution d = test::random_distribution(rng, 0.0, 1.0);
  double zf = std::clamp(random_fragment_depth(rng, d, 0.0, 1.0), min_zf, 1.0);
  return {std::move(d), zf};
}

// Cantelli's inequality, by hand, in double.
double cantelli(double mean, double variance, double zf) {
  if (zf <= mean) return 0.0;
  double d = zf - mean;
  return d * d / (variance + d * d);
}

vec2 vsm_float_moments(const test::Distribution& d) {
  return vec2(float(expect(d, [](double z) { return z; })), float(expect(d, [](double z) { return z * z; })));
}
vec2 vsm_theta2_unorm16_moments(const test::Distribution& d) {
  double b1 = expect(d, [](double z) { return z; }), b2 = expect(d, [](double z) { return z * z; });
  return msm_quantize_unorm16x2(vec2(float(b1), float(4.0 * (b1 - b2)))); // θ2 in double, then stored
}
vec4 evsm4_float_moments(const test::Distribution& d, double cp, double cn) {
  return vec4(float(expect(d, [cp](double z) { return std::exp(cp * z); })),
              float(expect(d, [cp](double z) { return std::exp(2.0 * cp * z); })),
              float(expect(d, [cn](double z) { return -std::exp(-cn * z); })),
              float(expect(d, [cn](double z) { return std::exp(-2.0 * cn * z); })));
}
CsmMoments csm_float_moments(const test::Distribution& d, int terms) {
  CsmMoments m = msm_csm_moments(0.0f, 0); // all zero
  for (int k = 1; k <= terms; ++k) {
    double ck = (2.0 * k - 1.0) * std::numbers::pi;
    float s = float(expect(d, [ck](double z) { return std::sin(ck * z); }));
    float c = float(expect(d, [ck](double z) { return std::cos(ck * z); }));
    int t = (k - 1) / 2, j = 2 * ((k - 1) % 2);
    vec4 v = msm_csm_texel(m, t);
    v[j] = s;
    v[j + 1] = c;
    if (t < 4)
      m.lo[t] = v;
    else
      m.hi[t - 4] = v;
  }
  return m;
}

// The plain truncated series in double: the reference for the float implementation.
double csm_series_double(const test::Distribution& d, double zf, int terms, double damping) {
  double s = 0.5;
  for (int k = 1; k <= terms; ++k) {
    double ck = (2.0 * k - 1.0) * std::numbers::pi, r = double(k) / terms;
    s += 2.0 * std::exp(-damping * r * r) / ck * expect(d, [&](double z) { return std::sin(ck * (zf - z)); });
  }
  return s;
}

// ------------------------------------------------------------------------------------------------
// θ2 (2015 §4.3): maps b([0,1]) into [0,1]², fills it, and gains log2|det θ2| = 2 bits.

TEST(Theta2, MapsTheUnitDepthCurveIntoTheUnitSquareAndGainsTwoBits) {
  float lo[2] = {1e9f, 1e9f}, hi[2] = {-1e9f, -1e9f};
  for (int i = 0; i <= 100000; ++i) {
    float z = float(i) / 100000.0f;
    vec2 q = msm_vsm_moments_theta2(z);
    for (int j = 0; j < 2; ++j) lo[j] = std::min(lo[j], q[j]), hi[j] = std::max(hi[j], q[j]);
    vec2 b = msm_theta2_inverse(q);
    // Inverse: exact up to float rounding of 4(z - z²) (|q| <= 1: a few ulps).
    ASSERT_NEAR(b[0], z, 1e-7f);
    ASSERT_NEAR(b[1], z * z, 4e-7f);
  }
  // The curve is (z, 4z(1-z)): its bounding box is exactly [0,1]² (b([0,1])'s convex hull, where
  // filtered texels lie, is then inside it because θ2 is affine).
  EXPECT_EQ(lo[0], 0.0f);
  EXPECT_EQ(hi[0], 1.0f);
  EXPECT_EQ(lo[1], 0.0f);
  EXPECT_EQ(hi[1], 1.0f);
  // |det| from the images of the unit vectors (θ2 is affine: subtract the image of 0).
  vec2 o = msm_theta2(vec2(0.0f)), e1 = msm_theta2(vec2(1.0f, 0.0f)) - o, e2 = msm_theta2(vec2(0.0f, 1.0f)) - o;
  double det = double(e1[0]) * e2[1] - double(e1[1]) * e2[0];
  std::printf("[theta2] bounding box [%g,%g]x[%g,%g], log2|det| = %.6f bits\n", lo[0], hi[0], lo[1], hi[1],
              std::log2(std::abs(det)));
  EXPECT_DOUBLE_EQ(std::log2(std::abs(det)), 2.0);
}

// The gain in practice: the error of σ² after 16-bit storage. Naive storage of (b1, b2) errs by
// up to (2 |b1| + 1) 0.5/65535 = 2.3e-5; θ2 by (|1 - 2 q1| + 1/4) 0.5/65535 <= 9.5e-6, the bound
// that MSM_VSM_MIN_VARIANCE_UNORM16 = 2e-5 is derived from (baselines.h).
TEST(Theta2, ReducesTheVarianceErrorOf16BitVsm) {
  std::mt19937_64 rng(11);
  double worst_naive = 0.0, worst_theta = 0.0;
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_distribution(rng, 0.0, 1.0);
    double b1 = expect(d, [](double z) { return z; }), b2 = expect(d, [](double z) { return z * z; });
    double var = b2 - b1 * b1;
    vec2 naive = msm_quantize_unorm16x2(vec2(float(b1), float(b2)));
    vec2 theta = msm_theta2_inverse(vsm_theta2_unorm16_moments(d));
    worst_naive = std::max(worst_naive, std::abs(double(naive[1]) - double(naive[0]) * naive[0] - var));
    worst_theta = std::max(worst_theta, std::abs(double(theta[1]) - double(theta[0]) * theta[0] - var));
  }
  std::printf("[theta2] worst |error of variance| after 16-bit storage: naive %.3e, theta2 %.3e\n", worst_naive,
              worst_theta);
  EXPECT_LE(worst_theta, 9.6e-6);            // the documented bound (plus float rounding)
  EXPECT_LT(worst_theta, 0.6 * worst_naive); // and a real gain
  EXPECT_LT(worst_theta, 0.5 * MSM_VSM_MIN_VARIANCE_UNORM16);
}

// ------------------------------------------------------------------------------------------------
// VSM

// Cantelli IS the sharp m = 2 bound (2015 §4.1): in double, JCGT Algorithm 1 with m = 2 agrees
// with the hand-written Cantelli to rounding (tolerance 1e-9: long double algebra on moments of
// variance >= ~1e-6, relative errors ~1e-12 after standardization).
TEST(Vsm, CantelliIsTheSharpTwoMomentBoundInDouble) {
  std::mt19937_64 rng(21);
  ErrorStats err;
  int branches[2] = {0, 0};
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    std::vector<double> b = test::power_moments(d, 2);
    double var = b[2] - b[1] * b[1];
    if (var < 1e-6) continue; // (nearly) one Dirac: B singular, the oracle's degenerate branch
    double zf = random_fragment_depth(rng, d, -1.0, 1.0);
    oracle::MomentBounds ref = oracle::moment_bounds(b, zf);
    ASSERT_TRUE(ref.ok) << ref.reason;
    ++branches[zf > b[1]];
    err.add(ref.lower - cantelli(b[1], var, zf));
  }
  std::printf("[vsm] JCGT Alg. 1 (m=2) vs Cantelli in double: n %zu max %.2e (zf<=mean %d, zf>mean %d)\n",
              err.errors.size(), err.max(), branches[0], branches[1]);
  EXPECT_GT(err.errors.size(), 15000u);
  EXPECT_GT(branches[0], 1000);
  EXPECT_GT(branches[1], 1000);
  EXPECT_LT(err.max(), 1e-9);
}

// The float implementation against the oracle (and the double Cantelli) on the same float
// moments, min_variance = 0 so that nothing but arithmetic differs. What remains is the float
// rounding of σ² = b2 - b1² (absolute ~1e-7), amplified by ∂shadow/∂σ² = d²/(σ² + d²)² <= 1/(4σ²)
// (which is largest for the narrowest distributions in the set). Tolerances: 99% within 1e-4,
// all within 2e-2 (measured values printed).
TEST(Vsm, EqualsTheMomentOracleWithTwoMoments) {
  std::mt19937_64 rng(22);
  ErrorStats err_oracle, err_hand;
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_distribution(rng, 0.0, 1.0);
    vec2 b = vsm_float_moments(d);
    double var = double(b[1]) - double(b[0]) * b[0];
    if (var < 1e-6) continue; // float moments of (nearly) one Dirac: see ExactForOneDirac
    float zf = float(random_fragment_depth(rng, d, 0.0, 1.0));
    std::vector<double> bd = {1.0, b[0], b[1]};
    oracle::MomentBounds ref = oracle::moment_bounds(bd, zf);
    ASSERT_TRUE(ref.ok) << ref.reason;
    float s = msm_vsm_shadow(b, zf, 0.0f);
    err_oracle.add(s - ref.lower);
    err_hand.add(s - cantelli(b[0], var, zf));
  }
  std::printf("[vsm float vs JCGT Alg. 1 m=2] n %zu p50 %.2e p99 %.2e max %.2e; vs double Cantelli max %.2e\n",
              err_oracle.errors.size(), err_oracle.quantile(0.5), err_oracle.quantile(0.99), err_oracle.max(),
              err_hand.max());
  EXPECT_GT(err_oracle.errors.size(), 15000u);
  EXPECT_LT(err_oracle.quantile(0.99), 1e-4);
  EXPECT_LT(err_oracle.max(), 2e-2);
  EXPECT_LT(err_hand.max(), 2e-2);
  test::record_figure("math.vsm_vs_alg1.error_p99", err_oracle.quantile(0.99),
                      {.below = 1e-4, .meaning = "VSM (Cantelli), float, vs JCGT Alg. 1 (m = 2): error, p99"});
  test::record_figure("math.vsm_vs_alg1.error_max", err_oracle.max(),
                      {.below = 2e-2, .meaning = "VSM (Cantelli), float, vs JCGT Alg. 1 (m = 2): error, max"});
}

// And against the LP on a wide grid (the stand-in for I = R): the same bound from the general
// moment problem. The grid's discreteness costs up to ~1e-3 (the LP can only put the escaping
// atom on grid points, and minimizes over fewer distributions: LP >= the bound over R).
TEST(Vsm, EqualsTheLinearProgramOnAWideGrid) {
  std::mt19937_64 rng(23);
  std::vector<double> grid = oracle::wide_grid(0.0, 1.0);
  oracle::Basis basis = oracle::power_basis(2);
  ErrorStats err;
  for (int i = 0; i < 150; ++i) {
    test::Distribution d = test::random_distribution(rng, 0.0, 1.0);
    std::vector<double> b = test::power_moments(d, 2);
    if (b[2] - b[1] * b[1] < 1e-5) continue;
    double zf = random_fragment_depth(rng, d, 0.0, 1.0);
    std::vector<double> bb = {b[1], b[2]};
    oracle::LpBounds lp = oracle::lp_bounds(grid, basis, bb, zf);
    ASSERT_TRUE(lp.feasible) << lp.status;
    float s = msm_vsm_shadow(vec2(float(b[1]), float(b[2])), float(zf), 0.0f);
    err.add(s - lp.lower);
    EXPECT_LE(s, lp.lower + 1e-4); // the LP's optimum over a subset is never below the bound
  }
  std::printf("[vsm vs LP on wide grid] n %zu p90 %.2e max %.2e\n", err.errors.size(), err.quantile(0.9), err.max());
  EXPECT_GT(err.errors.size(), 100u);
  EXPECT_LT(err.max(), 3e-3);
}

// Exactness: one Dirac occluder and a receiver behind it: shadow = d²/(v + d²) -> 1 as the
// (minimum) variance v -> 0, and exactly 1 - v/(v + d²) for each v.
TEST(Vsm, ExactForOneDiracAsVarianceVanishes) {
  std::mt19937_64 rng(24);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    float z0 = 0.9f * unit(rng), d = 0.01f + 0.09f * unit(rng);
    vec2 b = msm_vsm_moments(z0);
    float zf = z0 + d;
    double dd = double(zf) - z0; // the distance after float rounding of zf
    float previous = -1.0f;
    for (float v = 1e-2f; v >= 1e-9f; v *= 0.1f) {
      float s = msm_vsm_shadow(b, zf, v);
      // σ² of float Dirac moments is exactly 0 (b2 and b1² are the same rounded product),
      // so the minimum variance is the variance; the reference sees the same v and zf.
      { EXPECT_NEAR(s, dd * dd / (v + dd * dd), 1e-6) << z0 << " " << d << " " << v; }
      EXPECT_GT(s, previous);
      previous = s;
    }
    float s0 = msm_vsm_shadow(b, zf, 0.0f);
    EXPECT_EQ(s0, 1.0f);                          // σ² = 0: d²/d²
    EXPECT_EQ(msm_vsm_shadow(b, z0, 0.0f), 0.0f); // the receiver itself: lit, not 0/0
  }
  // Exactly: σ² = 0 in float for z0 = 0.5 (0.25 - 0.5² = 0).
  EXPECT_EQ(msm_vsm_shadow(msm_vsm_moments(0.5f), 0.6f, 0.0f), 1.0f);
}

// Why the 16-bit minimum variance is needed, and that the default suffices: a lone surface
// shading itself (zf = its own depth, the worst case for acne) after θ2 + 16-bit storage.
TEST(Vsm, MinimumVarianceRemovesSelfShadowingAfter16BitStorage) {
  float worst_default = 0.0f, worst_none = 0.0f;
  for (int i = 0; i <= 20000; ++i) {
    float z = float(i) / 20000.0f;
    vec2 q = msm_quantize_unorm16x2(msm_vsm_moments_theta2(z));
    worst_default = std::max(worst_default, msm_vsm_shadow_theta2(q, z));
    worst_none = std::max(worst_none, msm_vsm_shadow_theta2(q, z, 0.0f));
  }
  std::printf("[vsm 16-bit self-shadowing] worst shadow: min variance 0: %.3f, default %.2e: %.2e\n", worst_none,
              double(MSM_VSM_MIN_VARIANCE_UNORM16), worst_default);
  EXPECT_GT(worst_none, 0.5f); // rounding alone produces acne
  // The rounding of μ = q1 by <= 0.5/65535 = 7.63e-6 is the only error left at a lone surface:
  // d²/(v + d²) <= (7.63e-6)² / 2e-5 = 2.91e-6 (plus float rounding).
  EXPECT_LT(worst_default, 3.5e-6f);
}

// ------------------------------------------------------------------------------------------------
// Lower bounds of the true Z(z < zf) on random distributions (2015 §3).

struct LowerBoundCheck {
  const char* name;
  double tolerance;
  int violations = 0, total = 0;
  double worst = -1.0, leak = 0.0; // worst shadow - truth; mean truth - shadow (light leaking)
  void add(double shadow, double truth) {
    ++total;
    worst = std::max(worst, shadow - truth);
    leak += truth - shadow;
    if (shadow > truth + tolerance) ++violations;
  }
  void report() {
    std::printf("[lower bound] %-34s n %d worst shadow-truth %+.2e (tol %.0e) mean leak %.4f\n", name, total, worst,
                tolerance, leak / total);
    EXPECT_EQ(violations, 0) << name;
  }
};

// VSM in float: the float rounding of σ² (~1e-7) against the 1e-6 default minimum variance that
// only lowers the shadow: tolerance 1e-5 (a few ulps of the final division).
// VSM θ2 16-bit: the rounding of μ by up to 7.6e-6 moves the Cantelli value by up to
// |∂/∂μ| 7.6e-6 <= 0.65/σ 7.6e-6 ~ 1e-3 (σ >= sqrt(2e-5)); σ² is covered by the minimum
// variance: tolerance 2e-3.
TEST(LowerBound, Vsm) {
  std::mt19937_64 rng(31);
  LowerBoundCheck f{"VSM 64-bit float, min var 1e-6", 1e-5}, q{"VSM 32-bit theta2 unorm16", 2e-3};
  for (int i = 0; i < 30000; ++i) {
    const auto [d, zf] = unit_case(rng);
    double truth = test::cdf_less(d, zf);
    f.add(msm_vsm_shadow(vsm_float_moments(d), float(zf)), truth);
    q.add(msm_vsm_shadow_theta2(vsm_theta2_unorm16_moments(d), float(zf)), truth);
  }
  f.report();
  q.report();
}

// Markov holds for any distribution on R and any zf: tested on [0,1] with c = 80, on [-1,1] with
// c = 40 and on a wide range [-3, 2] with c = 10, zf anywhere (also inside and outside the
// support). Tolerance 1e-5: b is rounded to float (relative 6e-8) and multiplied by a float
// exp(-c zf) whose argument is rounded too (relative error c |zf| 6e-8 <= 5e-6 at c zf = 80).
TEST(LowerBound, Esm) {
  struct Case {
    double lo, hi, c;
    const char* name;
  };
  for (Case cs : {Case{0.0, 1.0, 80.0, "ESM c=80 on [0,1]"}, Case{-1.0, 1.0, 40.0, "ESM c=40 on [-1,1]"},
                  Case{-3.0, 2.0, 10.0, "ESM c=10 on [-3,2]"}}) {
    std::mt19937_64 rng(32);
    LowerBoundCheck check{cs.name, 1e-5};
    for (int i = 0; i < 30000; ++i) {
      test::Distribution d = test::random_distribution(rng, cs.lo, cs.hi);
      double zf = random_fragment_depth(rng, d, cs.lo, cs.hi);
      float b = float(expect(d, [&](double z) { return std::exp(cs.c * z); }));
      check.add(msm_esm_shadow(b, float(zf), float(cs.c)), test::cdf_less(d, zf));
    }
    check.report();
  }
}

// EVSM on [-1,1]. Float (64/128-bit): the warped moments are rounded to float; σ² = E w² - (E w)²
// cancels to a relative error ~2e-7 of E w², which the minimum variance (1e-7 depth units
// through the slope, i.e. 1e-7 (c w)²) covers: tolerance 1e-4 (float division and exp rounding
// of the receiver warp, relative c 6e-8 = 2.4e-6 at c = 40, amplified by the Cantelli slope).
// Half (32/64-bit): the rounding of E w (relative 4.9e-4) moves μ like a depth error of
// 4.9e-4/c = 9e-5 and the Cantelli value by up to ~0.65/σ 9e-5 with σ >= 1e-2 (min variance
// 1e-4): tolerance 1e-2.
TEST(LowerBound, Evsm) {
  std::mt19937_64 rng(33);
  const float cp128 = MSM_EVSM_C_POS_128BIT, cn128 = MSM_EVSM_C_NEG_128BIT, c64 = MSM_EVSM_C_64BIT;
  LowerBoundCheck e2f{"EVSM2 64-bit (2 x float, c+=40)", 1e-4}, e4f{"EVSM4 128-bit (4 x float)", 1e-4},
      e2h{"EVSM2 32-bit (2 x half, c=5.54)", 1e-2}, e4h{"EVSM4 64-bit (4 x half, c=5.54)", 1e-2};
  for (int i = 0; i < 30000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    double zf = std::clamp(random_fragment_depth(rng, d, -1.0, 1.0), -1.0, 1.0);
    double truth = test::cdf_less(d, zf);
    vec4 bf = evsm4_float_moments(d, cp128, cn128);
    vec4 bh = msm_quantize_half4(evsm4_float_moments(d, c64, c64));
    e2f.add(msm_evsm2_shadow(vec2(bf[0], bf[1]), float(zf), cp128, MSM_EVSM_MIN_VARIANCE_FLOAT), truth);
    e4f.add(msm_evsm4_shadow(bf, float(zf), cp128, cn128, MSM_EVSM_MIN_VARIANCE_FLOAT), truth);
    e2h.add(msm_evsm2_shadow(vec2(bh[0], bh[1]), float(zf), c64, MSM_EVSM_MIN_VARIANCE_HALF), truth);
    e4h.add(msm_evsm4_shadow(bh, float(zf), c64, c64, MSM_EVSM_MIN_VARIANCE_HALF), truth);
  }
  e2f.report();
  e4f.report();
  e2h.report();
  e4h.report();
}

// CSM with the default parameters (damping 2, scale 2, offset 0) for every M = 1..16: the lower
// bound argued in baselines.h. Tolerance 1e-5: the float sum of <= 16 terms of size <= 2/π with
// rounding ~1e-7 each, doubled by the scale.
TEST(LowerBound, CsmWithDefaultParameters) {
  std::mt19937_64 rng(34);
  LowerBoundCheck check{"CSM M=1..16, defaults", 1e-5};
  for (int i = 0; i < 6000; ++i) {
    const auto [d, zf] = unit_case(rng);
    CsmMoments m = csm_float_moments(d, MSM_CSM_MAX_TERMS);
    CsmParams p = msm_csm_default_params();
    p.terms = 1 + i % MSM_CSM_MAX_TERMS;
    check.add(msm_csm_shadow(m, float(zf), p), test::cdf_less(d, zf));
  }
  check.report();
}

// ------------------------------------------------------------------------------------------------
// ESM

// A random ESM case: a distribution on [0,1], a fragment depth in [min_zf, 1], the exponential
// moment b = E exp(c z), and the LP's bounds on the exponential basis over the grid.
struct EsmCase {
  double zf, b;
  oracle::LpBounds lp;
};
EsmCase esm_case(std::mt19937_64& rng, const std::vector<double>& grid, double c, double min_zf) {
  const auto [d, zf] = unit_case(rng, min_zf);
  std::vector<double> b = {expect(d, [c](double z) { return std::exp(c * z); })};
  oracle::LpBounds lp = oracle::lp_bounds(grid, oracle::exponential_basis(std::vector<double>{c}), b, zf);
  return {zf, b[0], lp};
}

// ESM is the sharp bound of the exponential basis over I = R (2015 §3): against the LP (the
// oracle's exponential basis factory, b(z) = exp(c z)) on a grid [lo, 1] of 2001 points whose
// left end stands in for -infinity. On [lo, 1] the sharp bound is
// 1 - (b - e^{c lo}) / (e^{c zf} - e^{c lo}), which differs from Markov by at most e^{c lo}
// (for zf >= 0); lo = -25/c makes that 1.4e-11. Tolerance 1e-5: float ESM (rounding of b and of
// c zf, <= 2e-6) plus the LP's tolerances. c = 5, 10, 20 keep the LP row within e^45 of itself;
// at the default c = 80 it would span e^105 (no double LP is meaningful), and LowerBound.Esm
// covers c = 80 (the Markov argument does not depend on c).
TEST(Esm, EqualsTheLinearProgramForTheExponentialBasis) {
  for (double c : {5.0, 10.0, 20.0}) {
    std::mt19937_64 rng(41);
    const double lo = -25.0 / c, tolerance = 1e-5;
    std::vector<double> grid = oracle::uniform_grid(lo, 1.0, 2001);
    ErrorStats err;
    int positive = 0;
    for (int i = 0; i < 200; ++i) {
      const auto [zf, b, lp] = esm_case(rng, grid, c, 0.0);
      ASSERT_TRUE(lp.feasible) << lp.status << " c " << c << " b " << b << " zf " << zf;
      float s = msm_esm_shadow(float(b), float(zf), float(c));
      positive += s > 0.0f;
      err.add(s - lp.lower);
      EXPECT_NEAR(s, lp.lower, tolerance) << "c " << c << " b " << b << " zf " << zf << " LP residual " << lp.residual;
    }
    std::printf("[esm vs LP, c = %g, grid [%g,1]] n %zu (shadow > 0: %d) p90 %.2e max %.2e\n", c, lo, err.errors.size(),
                positive, err.quantile(0.9), err.max());
    test::record_figure(fmt::format("math.esm_c{:g}_vs_lp.error_max", c), err.max(),
                        {.below = tolerance,
                         .meaning = fmt::format("ESM, c = {:g}, vs the 2015 LP, exponential basis: error, max "
                                                "(each case within the bound)",
                                                c)});
    EXPECT_GT(positive, 50);
  }
}

// ... but not on I = [0,1]: there the sharp bound is 1 - (b - 1)/(exp(c zf) - 1) (mass at 0 and
// zf), which the LP on a [0,1] grid reproduces and which exceeds Markov by up to ~(1 - b e^{-c zf})
// / (e^{c zf} - 1). Checked at c = 5 where the difference is large enough to see.
TEST(Esm, IsNotSharpOnTheUnitInterval) {
  const double c = 5.0;
  std::mt19937_64 rng(42);
  std::vector<double> grid = oracle::uniform_grid(0.0, 1.0, 1001);
  double largest_gain = 0.0;
  for (int i = 0; i < 100; ++i) {
    const auto [zf, b, lp] = esm_case(rng, grid, c, 0.001);
    ASSERT_TRUE(lp.feasible) << lp.status;
    double sharp = std::clamp(1.0 - (b - 1.0) / (std::exp(c * zf) - 1.0), 0.0, 1.0);
    EXPECT_NEAR(lp.lower, sharp, 1e-6); // LP simplex tolerance
    float s = msm_esm_shadow(float(b), float(zf), float(c));
    EXPECT_LE(s, sharp + 1e-5);
    largest_gain = std::max(largest_gain, sharp - s);
  }
  std::printf("[esm on [0,1], c = 5] largest gain of the sharp bound over Markov: %.3f\n", largest_gain);
  EXPECT_GT(largest_gain, 0.05);
}

// The documented depth-convention rule: c on [0,1] depth == c/2 on [-1,1] depth.
TEST(Esm, UnitDepthWithCEqualsSignedDepthWithHalfC) {
  std::mt19937_64 rng(43);
  ErrorStats err;
  for (int i = 0; i < 20000; ++i) {
    const auto [d, zf] = unit_case(rng);
    float bu = float(expect(d, [](double z) { return std::exp(80.0 * z); }));
    float bs = float(expect(d, [](double z) { return std::exp(40.0 * (2.0 * z - 1.0)); }));
    err.add(msm_esm_shadow(bu, float(zf), 80.0f) - msm_esm_shadow(bs, float(2.0 * zf - 1.0), 40.0f));
  }
  std::printf("[esm c=80 on [0,1] vs c=40 on [-1,1]] max %.2e\n", err.max());
  EXPECT_LT(err.max(), 2e-5); // float rounding of both exponentials (c |z| 6e-8 each)
}

// Log-space filtering gives the same shadows as linear filtering (Salvi 2008): a filter folded
// tap by tap with msm_esm_log_mix. Tolerance 2e-5: log/exp rounding of arguments up to 80.
TEST(Esm, LogSpaceFilteringMatchesLinearFiltering) {
  std::mt19937_64 rng(44);
  std::uniform_int_distribution<int> count(1, 8);
  ErrorStats err;
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_diracs(rng, count(rng), 0.0, 1.0);
    double zf = std::clamp(random_fragment_depth(rng, d, 0.0, 1.0), 0.0, 1.0);
    const float c = MSM_ESM_C_DEFAULT;
    float log_b = msm_esm_log_moment(float(d.z[0]), c);
    double weight = d.w[0];
    for (size_t j = 1; j < d.z.size(); ++j) {
      log_b = msm_esm_log_mix(log_b, msm_esm_log_moment(float(d.z[j]), c), float(d.w[j] / (weight + d.w[j])));
      weight += d.w[j];
    }
    float b = float(expect(d, [c](double z) { return std::exp(double(c) * z); }));
    err.add(msm_esm_shadow_log(log_b, float(zf), c) - msm_esm_shadow(b, float(zf), c));
  }
  std::printf("[esm log-space vs linear filtering] max %.2e\n", err.max());
  EXPECT_LT(err.max(), 2e-5);
}

// ------------------------------------------------------------------------------------------------
// EVSM

// The exponents of config.h are the largest that the channel formats hold: the squared warp
// exp(2c) at |z| = 1 must stay finite. 16-bit float: max 65504 = exp(11.0898).
TEST(Evsm, ExponentsFitTheirChannelFormats) {
  EXPECT_GE(0.5 * std::log(65504.0), double(MSM_EVSM_C_64BIT));
  EXPECT_LT(0.5 * std::log(65504.0), double(MSM_EVSM_C_64BIT) + 0.01); // and 5.55 would not fit
  for (int i = 0; i <= 2000; ++i) {
    float z = -1.0f + float(i) / 1000.0f;
    vec4 h = msm_quantize_half4(msm_evsm4_moments(z, MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT));
    vec4 f = msm_evsm4_moments(z, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT);
    for (int j = 0; j < 4; ++j) {
      ASSERT_TRUE(std::isfinite(h[j])) << z;
      ASSERT_TRUE(std::isfinite(f[j])) << z;
      // Half keeps 11 significant bits (relative rounding <= 2^-11 = 4.88e-4) where the
      // value is a normal half (>= 6.1e-5); only exp(-2c) near |z| = 1 is subnormal.
      vec4 ref = msm_evsm4_moments(z, MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT);
      if (std::abs(ref[j]) >= 6.1e-5f) { ASSERT_NEAR(h[j] / ref[j], 1.0f, 4.9e-4f) << z << " " << j; }
    }
  }
  // Depths outside [-1,1] are clamped, so nothing overflows for receivers or occluders beyond
  // the clip planes.
  for (float z : {-100.0f, -2.0f, 2.0f, 100.0f}) {
    float zc = std::clamp(z, -1.0f, 1.0f);
    vec4 b = msm_evsm4_moments(z, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT);
    EXPECT_EQ(b, msm_evsm4_moments(zc, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT)) << z;
    EXPECT_EQ(msm_evsm2_moments(z, MSM_EVSM_C_POS_128BIT), msm_evsm2_moments(zc, MSM_EVSM_C_POS_128BIT)) << z;
    vec4 occluder = msm_evsm4_moments(0.5f, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT);
    EXPECT_EQ(msm_evsm4_shadow(occluder, z, 40.0f, 5.54f, 1e-6f), msm_evsm4_shadow(occluder, zc, 40.0f, 5.54f, 1e-6f));
  }
  vec2 over = msm_quantize_half2(vec2(std::exp(2.0f * 5.55f), std::exp(2.0f * 5.54f)));
  std::printf("[evsm] exp(5.54) = %.1f, exp(11.08) -> half %.0f, exp(11.10) -> half %f; exp(80) = %.3e (float)\n",
              std::exp(5.54), double(over[1]), double(over[0]), std::exp(80.0));
  EXPECT_TRUE(std::isinf(over[0]));
  EXPECT_TRUE(std::isfinite(over[1]));
  EXPECT_LT(2.0 * MSM_EVSM_C_POS_128BIT, std::log(double(std::numeric_limits<float>::max())));
}

// EVSM4 returns the darker of the two warps, so it is at least EVSM2 with the same c+.
TEST(Evsm, FourComponentsAreTheDarkerOfTheTwoWarps) {
  std::mt19937_64 rng(51);
  for (int i = 0; i < 5000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    float zf = float(std::clamp(random_fragment_depth(rng, d, -1.0, 1.0), -1.0, 1.0));
    vec4 b = evsm4_float_moments(d, 40.0, 5.54);
    float s4 = msm_evsm4_shadow(b, zf, 40.0f, 5.54f, 1e-6f);
    float s2 = msm_evsm2_shadow(vec2(b[0], b[1]), zf, 40.0f, 1e-6f);
    float sn = msm_evsm_warped_shadow(vec2(b[2], b[3]), -std::exp(-5.54f * zf), 5.54f * std::exp(-5.54f * zf), 1e-6f);
    EXPECT_EQ(s4, std::max(s2, sn));
  }
}

// The ordering the papers report: EVSM leaks less light than VSM where several surfaces overlap
// in the filter region. Case: occluders at depths a < b, receiver at r slightly behind b, so the
// truth is 1 and VSM leaks (the classic light bleeding: d = r - μ is small against σ).
TEST(Evsm, LeaksLessLightThanVsmWithThreeSurfaces) {
  struct Case {
    double a, wa, b, r;
  };
  for (Case cs : {Case{-0.6, 0.5, 0.2, 0.25}, Case{-0.9, 0.3, 0.5, 0.55}, Case{0.0, 0.7, 0.6, 0.65},
                  Case{-0.5, 0.5, -0.2, -0.15}}) {
    test::Distribution d{{cs.a, cs.b}, {cs.wa, 1.0 - cs.wa}};
    float r = float(cs.r);
    float vsm = msm_vsm_shadow(vsm_float_moments(d), r); // depth convention: any ([-1,1] here)
    float e4f = msm_evsm4_shadow(evsm4_float_moments(d, 40.0, 5.54), r, 40.0f, 5.54f, MSM_EVSM_MIN_VARIANCE_FLOAT);
    float e4h = msm_evsm4_shadow(msm_quantize_half4(evsm4_float_moments(d, 5.54, 5.54)), r, 5.54f, 5.54f,
                                 MSM_EVSM_MIN_VARIANCE_HALF);
    std::printf("[3 surfaces a=%.2f (w %.1f) b=%.2f r=%.2f] leak: VSM %.3f, EVSM4 64-bit %.3f, EVSM4 128-bit %.2e\n",
                cs.a, cs.wa, cs.b, cs.r, 1.0 - vsm, 1.0 - e4h, 1.0 - e4f);
    EXPECT_GT(1.0f - vsm, 0.2f); // the case does provoke VSM
    EXPECT_LT(1.0f - e4h, 1.0f - vsm);
    EXPECT_LT(1.0f - e4f, 0.1f * (1.0f - vsm));
  }
}

// And on average over random distributions on [-1,1] (mean light leaking E[truth - shadow]):
// (a) receivers behind every occluder (truth 1: the leaking in fully shadowed regions that the
// papers show), (b) receivers anywhere. In (b) the large c+ = 40 of the 128-bit variant does not
// help: where occluders lie behind the receiver, exp(40 z) of those dominates E w+ and the
// positive warp returns 0 (the ESM failure at receiver boundaries, 2015 §2), leaving the
// c- = 5.54 warp alone; measured, 128-bit then leaks slightly more than 64-bit, still less than VSM.
TEST(Evsm, LeaksLessLightThanVsmOnAverage) {
  std::mt19937_64 rng(52);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int n = 20000;
  for (bool behind : {true, false}) {
    double leak_vsm = 0.0, leak_e4f = 0.0, leak_e4h = 0.0;
    for (int i = 0; i < n; ++i) {
      test::Distribution d = test::random_distribution(rng, -1.0, behind ? 0.7 : 1.0);
      double zf = behind ? *std::max_element(d.z.begin(), d.z.end()) + 0.01 + 0.29 * unit(rng)
                         : std::clamp(random_fragment_depth(rng, d, -1.0, 1.0), -1.0, 1.0);
      double truth = test::cdf_less(d, zf);
      float z = float(zf);
      leak_vsm += truth - msm_vsm_shadow(vsm_float_moments(d), z);
      leak_e4f +=
          truth - msm_evsm4_shadow(evsm4_float_moments(d, 40.0, 5.54), z, 40.0f, 5.54f, MSM_EVSM_MIN_VARIANCE_FLOAT);
      leak_e4h += truth - msm_evsm4_shadow(msm_quantize_half4(evsm4_float_moments(d, 5.54, 5.54)), z, 5.54f, 5.54f,
                                           MSM_EVSM_MIN_VARIANCE_HALF);
    }
    std::printf("[mean light leaking, %s] VSM %.4f, EVSM4 64-bit %.4f, EVSM4 128-bit %.4f\n",
                behind ? "receiver behind all occluders" : "receiver anywhere", leak_vsm / n, leak_e4h / n,
                leak_e4f / n);
    EXPECT_LT(leak_e4h, leak_vsm);
    EXPECT_LT(leak_e4f, leak_vsm);
    if (behind) {
      EXPECT_LT(leak_e4f, 0.5 * leak_vsm);
      EXPECT_LT(leak_e4f, leak_e4h);
    }
  }
}

// Self-shadowing of a lone surface (zf = its depth) after half storage: the default minimum
// variance removes the acne that the half rounding of E w and E w² produces.
TEST(Evsm, MinimumVarianceRemovesSelfShadowingAfterHalfStorage) {
  float worst_default = 0.0f, worst_none = 0.0f;
  for (int i = 0; i <= 20000; ++i) {
    float z = -1.0f + float(i) / 10000.0f;
    vec4 b = msm_quantize_half4(msm_evsm4_moments(z, MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT));
    worst_default =
        std::max(worst_default, msm_evsm4_shadow(b, z, MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT, MSM_EVSM_MIN_VARIANCE_HALF));
    worst_none = std::max(worst_none, msm_evsm4_shadow(b, z, MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT, 0.0f));
  }
  std::printf("[evsm 64-bit self-shadowing] worst shadow: min variance 0: %.3f, default %.0e: %.2e\n", worst_none,
              double(MSM_EVSM_MIN_VARIANCE_HALF), worst_default);
  // Measured: 7.7e-5 with the default 1e-4; a minimum variance of 1e-5 gives 8e-4, 1e-6 gives 8e-3,
  // 1e-7 gives 0.07 and 0 gives 1 (acne), so the default is where acne has become invisible.
  EXPECT_GT(worst_none, 0.5f);
  EXPECT_LT(worst_default, 3e-4f);
}

// The float defaults: a flat surface filtered in float (9x9 Gaussian, σ = 2.4 texels, the 2015
// §3.2 kernel, accumulated and normalized in float as a blur pass does) and shading itself. The
// normalized sum of 81 equal moments differs from the moment by rounding, which makes μ < zf and
// σ² ~ 0 possible: acne without a minimum variance. Measured: none at the defaults, and the
// defaults are >= 10x what removes it (1e-9 for EVSM4-128, 1e-8 for VSM).
TEST(Evsm, FloatMinimumVariancesRemoveSelfShadowingAfterFloatFiltering) {
  std::mt19937_64 rng(53);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  float worst[2][2] = {{0.0f, 0.0f}, {0.0f, 0.0f}}; // [VSM, EVSM4][none, default]
  for (int i = 0; i < 4000; ++i) {
    float z = -1.0f + 2.0f * unit(rng), zu = 0.5f * z + 0.5f;
    vec4 e(0.0f);
    vec2 v(0.0f);
    float weight = 0.0f;
    for (int x = -4; x <= 4; ++x) {
      for (int y = -4; y <= 4; ++y) {
        float w = std::exp(-float(x * x + y * y) / (2.0f * 2.4f * 2.4f));
        e += w * msm_evsm4_moments(z, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT);
        v += w * msm_vsm_moments(zu);
        weight += w;
      }
    }
    e /= weight;
    v /= weight;
    worst[0][0] = std::max(worst[0][0], msm_vsm_shadow(v, zu, 0.0f));
    worst[0][1] = std::max(worst[0][1], msm_vsm_shadow(v, zu, MSM_VSM_MIN_VARIANCE_FLOAT));
    worst[1][0] = std::max(worst[1][0], msm_evsm4_shadow(e, z, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT, 0.0f));
    worst[1][1] = std::max(
        worst[1][1], msm_evsm4_shadow(e, z, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT, MSM_EVSM_MIN_VARIANCE_FLOAT));
  }
  std::printf("[float self-shadowing after a float 9x9 blur] VSM: %.3f without, %.1e default; EVSM4-128: %.3f "
              "without, %.1e default\n",
              worst[0][0], worst[0][1], worst[1][0], worst[1][1]);
  EXPECT_GT(worst[0][0], 0.5f);
  EXPECT_GT(worst[1][0], 0.5f);
  EXPECT_LT(worst[0][1], 1e-4f);
  EXPECT_LT(worst[1][1], 1e-4f);
}

// ------------------------------------------------------------------------------------------------
// CSM

// The storage layout: texel t holds terms 2t+1, 2t+2 as (sin, cos, sin, cos); terms beyond M are
// zero; the texel-wise sum equals the struct interface.
TEST(Csm, TexelLayoutAndInterfacesAgree) {
  for (int terms = 1; terms <= MSM_CSM_MAX_TERMS; ++terms) {
    float z = 0.37f, zf = 0.61f;
    CsmMoments m = msm_csm_moments(z, terms);
    CsmParams p = msm_csm_default_params();
    p.terms = terms;
    float sum = 0.0f;
    for (int t = 0; t < MSM_CSM_MAX_TEXELS; ++t) {
      vec4 v = msm_csm_texel(m, t);
      for (int j = 0; j < 4; ++j) {
        int k = 2 * t + 1 + j / 2;
        float a = float(2 * k - 1) * MSM_PI * z;
        float expected = k > terms ? 0.0f : (j % 2 ? std::cos(a) : std::sin(a));
        EXPECT_NEAR(v[j], expected, 1e-6f) << terms << " " << t << " " << j;
      }
      sum += msm_csm_texel_terms(v, msm_csm_receiver(zf, p), t, p);
      EXPECT_NEAR(msm_csm_from_unorm(msm_csm_to_unorm(v))[0], v[0], 1e-6f);
    }
    EXPECT_NEAR(msm_csm_resolve(sum, p), msm_csm_shadow(m, zf, p), 1e-6f);
  }
}

// The float series equals the double series (implementation check, tolerance 2e-6: float sin/cos
// of arguments up to 31π, about 16 terms).
TEST(Csm, SeriesMatchesDoublePrecision) {
  std::mt19937_64 rng(61);
  ErrorStats err;
  for (int i = 0; i < 3000; ++i) {
    const auto [d, zf] = unit_case(rng);
    int terms = 1 + i % 16;
    double damping = (i % 3) * 1.0;
    CsmParams p = CsmParams(terms, float(damping), 1.0f, 0.0f);
    err.add(msm_csm_series(csm_float_moments(d, terms), float(zf), p) - csm_series_double(d, zf, terms, damping));
  }
  std::printf("[csm float vs double series] max %.2e\n", err.max());
  EXPECT_LT(err.max(), 2e-5);
}

// Convergence: the plain truncated series tends to the filtered step Z(z < zf) as M grows, away
// from the discontinuities (every |zf - z_i| >= 0.1, and |zf - z_i| <= 0.9 so that the jump of
// the periodic extension at |x| = 1 is as far away). The tail of the series at distance δ from a
// jump is O(1/(M δ)): the error must shrink like 1/M.
TEST(Csm, ConvergesToTheFilteredStepAwayFromDiscontinuities) {
  std::mt19937_64 rng(62);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> count(1, 8);
  double worst[5] = {0, 0, 0, 0, 0};
  const int Ms[5] = {1, 2, 4, 8, 16};
  int cases = 0;
  while (cases < 2000) {
    test::Distribution d = test::random_diracs(rng, count(rng), 0.05, 0.95);
    double zf = 0.05 + 0.9 * unit(rng);
    bool far = true;
    for (double z : d.z) far = far && std::abs(zf - z) >= 0.1;
    if (!far) continue;
    ++cases;
    CsmMoments m = csm_float_moments(d, 16);
    for (int j = 0; j < 5; ++j)
      worst[j] = std::max(worst[j],
                          std::abs(msm_csm_series(m, float(zf), msm_csm_plain_params(Ms[j])) - test::cdf_less(d, zf)));
  }
  std::printf("[csm convergence, distance >= 0.1] worst error M=1 %.3f, 2 %.3f, 4 %.3f, 8 %.3f, 16 %.4f\n", worst[0],
              worst[1], worst[2], worst[3], worst[4]);
  for (int j = 1; j < 5; ++j) EXPECT_LT(worst[j], worst[j - 1]);
  EXPECT_LT(worst[4], 0.6 * worst[3]); // ~halves per doubling of M
  EXPECT_LT(worst[4], 0.05);
}

// Ringing at small M: one occluder, the plain series overshoots 1 and undershoots 0 by about 9%
// (Gibbs, for every M), and the damping of the defaults removes the overshoot.
TEST(Csm, RingsWithoutDampingAndNotWithIt) {
  for (int terms : {2, 4, 8, 16}) {
    CsmMoments m = msm_csm_moments(0.5f, terms);
    CsmParams plain = msm_csm_plain_params(terms), damped = msm_csm_plain_params(terms);
    damped.damping = MSM_CSM_DAMPING_DEFAULT;
    float hi = -1.0f, lo = 2.0f, damped_hi = -1.0f, damped_lo = 2.0f;
    for (int i = 0; i <= 10000; ++i) {
      float zf = float(i) / 10000.0f;
      float s = msm_csm_series(m, zf, plain), sd = msm_csm_series(m, zf, damped);
      hi = std::max(hi, s), lo = std::min(lo, s);
      damped_hi = std::max(damped_hi, sd), damped_lo = std::min(damped_lo, sd);
    }
    std::printf("[csm ringing, M=%d] plain series in [%.4f, %.4f], damped (2) in [%.4f, %.4f]\n", terms, lo, hi,
                damped_lo, damped_hi);
    EXPECT_GT(hi, 1.08f); // Gibbs: 1.0895 in the limit, more for small M
    EXPECT_LT(lo, -0.08f);
    EXPECT_LE(damped_hi, 1.0f);
    EXPECT_GE(damped_lo, 0.0f);
  }
}

// The documented light leaking of the defaults behind a lone occluder (2 S_M(x) - 1 = 0.9).
TEST(Csm, DefaultsReachNinetyPercentShadowBehindAnOccluder) {
  for (int terms : {4, 16}) {
    CsmParams p = msm_csm_default_params();
    p.terms = terms;
    CsmMoments m = msm_csm_moments(0.3f, terms);
    float x90 = -1.0f;
    for (int i = 0; i <= 7000; ++i) {
      float x = float(i) / 10000.0f;
      if (msm_csm_shadow(m, 0.3f + x, p) >= 0.9f) {
        x90 = x;
        break;
      }
    }
    std::printf("[csm defaults, M=%d] 90%% shadow at distance %.4f behind the occluder\n", terms, x90);
    EXPECT_NEAR(x90, terms == 4 ? 0.247f : 0.035f, 0.005f);
    EXPECT_EQ(msm_csm_shadow(m, 0.3f, p), 0.0f); // no acne at the occluder itself
  }
}

// ------------------------------------------------------------------------------------------------
// Over-darkening and light-bleeding reduction

TEST(Overdarken, ClampsAboveTheFactorAndScalesBelow) {
  const float factor = MSM_OVERDARKEN_DEFAULT;
  EXPECT_EQ(factor, 0.98f);
  EXPECT_EQ(msm_overdarken(0.0f), 0.0f);
  EXPECT_EQ(msm_overdarken(1.0f), 1.0f);
  EXPECT_EQ(msm_overdarken(factor), 1.0f); // leaking of 2% and less disappears
  EXPECT_EQ(msm_overdarken(0.99f), 1.0f);
  float previous = -1.0f;
  for (int i = 0; i <= 10000; ++i) {
    float s = float(i) / 10000.0f;
    float o = msm_overdarken(s, factor);
    if (s >= factor) {
      EXPECT_EQ(o, 1.0f) << s;
    } else {
      EXPECT_FLOAT_EQ(o, s / factor) << s; // linear up to the factor
    }
    EXPECT_GE(o, s); // never lightens
    EXPECT_GE(o, previous);
    previous = o;
  }
  EXPECT_EQ(msm_overdarken(0.5f, 1.0f), 0.5f);  // factor 1: off
  EXPECT_EQ(msm_overdarken(-0.1f, 0.9f), 0.0f); // clamped below too
}

TEST(Overdarken, VsmLightBleedingReductionIsOverdarkeningByOneMinusAmount) {
  for (float amount : {0.0f, 0.1f, 0.2f, 0.3f, 0.5f}) {
    for (int i = 0; i <= 1000; ++i) {
      float s = float(i) / 1000.0f;
      EXPECT_NEAR(msm_vsm_reduce_light_bleeding(s, amount), msm_overdarken(s, 1.0f - amount), 2e-6f);
    }
  }
  EXPECT_EQ(msm_vsm_reduce_light_bleeding(0.3f, 0.0f), 0.3f);   // amount 0: off
  EXPECT_EQ(msm_vsm_reduce_light_bleeding(0.75f, 0.25f), 1.0f); // lit fractions below 0.25 vanish
}

} // namespace
