// Average blocker depth for moment soft shadows (JCGT Eq. (4), Kneiphof Eq. (19)) with four and
// six moments: exactness for the configurations the papers claim, the unoccluded case, the
// identity between the two formulas, and agreement with the canonical distributions of the
// double-precision moment oracle (JCGT Algorithm 1, m = 4 and 6).
#include "msm/bias.h"
#include "msm/blocker.h"
#include "msm/config.h"
#include "msm/oracle/moment_oracle.h"
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

// Biased float moments as the blocker search gets them: four moments from a [-1,1] float map
// (JCGT: α = 3e-7), six moments from a float map (JCGT §5.4.3: α = 5e-6).
vec4 biased_moments4(const test::Distribution& d) {
  return msm_apply_bias(test::moments4f(d), msm_moment_bias(MSM_REP_SIGNED_FLOAT));
}
Moments6 biased_moments6(const test::Distribution& d) {
  std::vector<double> b = test::power_moments(d, 6);
  Moments6 m = Moments6{vec3(float(b[1]), float(b[3]), float(b[5])), vec3(float(b[2]), float(b[4]), float(b[6]))};
  return msm_apply_bias6(m, msm_moment_bias6(MSM_REP6_FLOAT));
}

float uniform_float(std::mt19937_64& rng, float lo, float hi) {
  return std::uniform_real_distribution<float>(lo, hi)(rng);
}

test::Distribution diracs(std::vector<double> z, std::vector<double> w) { return test::Distribution{z, w}; }

// JCGT Eq. (4) on a discrete distribution, in double: the blockers are the depths below zf. The
// average is then clamped to the depth range [-1, 1] as the authors' code does (a receiver in
// front of the range keeps its own depth), which is what blocker.h promises.
struct Reference {
  double depth, shadow;
};
Reference equation4(const std::vector<double>& z, const std::vector<double>& w, double zf, double epsilon) {
  double weight = 0.0, depth = 0.0;
  for (size_t l = 0; l < z.size(); ++l)
    if (z[l] < zf) {
      weight += w[l];
      depth += w[l] * z[l];
    }
  double average = (epsilon * zf + depth) / (epsilon + weight);
  return {average > -1.0 ? std::min(average, 1.0) : std::min(zf, -1.0), weight};
}

// JCGT §4.3: one occluder at z1 < zf with weight w1 and the receiver at zf (the UNBIASED fragment
// depth, so 2015 Prop. 8 applies) are reconstructed nearly perfectly, so the average blocker
// depth is (ε zf + w1 z1) / (ε + w1) and the shadow w1. For six moments the same holds with two
// occluders (three depths, one of them at zf). Occluders at least 0.05 in front of zf.
// What is left is the bias: the biased moments are not exactly those of the configuration, and
// the canonical distribution moves (the m = 6 oracle on the same moments moves identically: for
// two occluders its shadow is off by the same p99 4e-3, max 2.8e-2), plus float. The depth error
// is measured relative to the blocker distance zf - expected, which sets the penumbra width.
// Measured (seed 71): 4 moments: depth relative max 1.4e-3, shadow max 5.0e-4; 6 moments, one
// occluder: depth relative max 6.5e-3, shadow max 2.7e-4; two occluders: depth relative p99
// 6.8e-3, max 5.3e-2, shadow p99 4.4e-3, max 2.8e-2. Tolerances: 4 moments 5e-3 relative and
// 2e-3; 6 moments one occluder 0.03 and 3e-3; two occluders 0.15 and 0.08. Misreading the paper (counting z0, or the roots above
// zf, or averaging without ε) moves the depth by O(1) relative in most cases.
TEST(Blocker, OccludersInFrontOfTheReceiverAreExact) {
  std::mt19937_64 rng(71);
  const double eps = MSM_BLOCKER_EPSILON;
  ErrorStats depth4, shadow4, depth6, shadow6, depth6_two, shadow6_two;
  for (int i = 0; i < 20000; ++i) {
    float zf = uniform_float(rng, -0.8f, 1.0f);
    double z1 = uniform_float(rng, -1.0f, zf - 0.05f);
    double w1 = uniform_float(rng, 0.02f, 0.98f);
    test::Distribution two = diracs({z1, zf}, {w1, 1.0 - w1});
    double expected = (eps * zf + w1 * z1) / (eps + w1);
    double distance = zf - expected;
    BlockerResult r4 = msm_blocker4(biased_moments4(two), zf);
    BlockerResult r6 = msm_blocker6(biased_moments6(two), zf);
    depth4.add((r4.depth - expected) / distance);
    shadow4.add(r4.shadow - w1);
    depth6.add((r6.depth - expected) / distance);
    shadow6.add(r6.shadow - w1);
    EXPECT_NEAR(r4.depth, expected, 5e-3 * distance) << "case " << i << " zf " << zf << " z1 " << z1 << " w1 " << w1;
    EXPECT_NEAR(r4.shadow, w1, 2e-3) << "case " << i;
    EXPECT_NEAR(r6.depth, expected, 0.03 * distance) << "case " << i << " zf " << zf << " z1 " << z1 << " w1 " << w1;
    EXPECT_NEAR(r6.shadow, w1, 3e-3) << "case " << i;
    // Six moments: a second occluder z2 < zf.
    double z2 = uniform_float(rng, -1.0f, zf - 0.05f);
    if (std::abs(z2 - z1) < 0.05) continue;
    double w2 = uniform_float(rng, 0.02f, 0.98f) * (1.0 - w1);
    test::Distribution three = diracs({z1, z2, zf}, {w1, w2, 1.0 - w1 - w2});
    double expected3 = (eps * zf + w1 * z1 + w2 * z2) / (eps + w1 + w2);
    BlockerResult r3 = msm_blocker6(biased_moments6(three), zf);
    depth6_two.add((r3.depth - expected3) / (zf - expected3));
    shadow6_two.add(r3.shadow - (w1 + w2));
    EXPECT_NEAR(r3.depth, expected3, 0.15 * (zf - expected3))
        << "case " << i << " zf " << zf << " z " << z1 << " " << z2;
    EXPECT_NEAR(r3.shadow, w1 + w2, 0.08) << "case " << i;
  }
  std::printf("[blocker, occluders + receiver at zf] depth error relative to zf - depth, shadow error: 4 moments: "
              "depth p99 %.2e max %.2e, shadow max %.2e; 6 moments: depth p99 %.2e max %.2e, shadow max %.2e; "
              "6 moments, two occluders: depth p99 %.2e max %.2e, shadow p99 %.2e max %.2e\n",
              depth4.quantile(0.99), depth4.max(), shadow4.max(), depth6.quantile(0.99), depth6.max(), shadow6.max(),
              depth6_two.quantile(0.99), depth6_two.max(), shadow6_two.quantile(0.99), shadow6_two.max());
}

// An unoccluded fragment (every depth at or behind zf: the receiver itself and up to two surfaces
// behind it, or a continuous distribution behind it) returns its own depth and no shadow.
// Spurious roots below zf carry the bias' weight; Eq. (4) divides it by ε. Measured (seed 72):
// |depth - zf| max 4 moments 3.7e-4, 6 moments 4.6e-3; shadow max 3.7e-7 / 3.5e-6.
// Tolerances 4 moments 3e-3 / 1e-4, 6 moments 0.015 / 1e-4.
TEST(Blocker, UnoccludedFragmentReturnsItsOwnDepth) {
  std::mt19937_64 rng(72);
  ErrorStats depth4, shadow4, depth6, shadow6;
  for (int i = 0; i < 20000; ++i) {
    float zf = uniform_float(rng, -1.0f, 0.9f);
    test::Distribution d;
    if (i % 4 == 3) {
      d = test::random_continuous(rng, zf + 0.05, 1.0);
    } else {
      d = diracs({zf}, {uniform_float(rng, 0.02f, 1.0f)});
      for (int k = 0; k < i % 3; ++k) {
        d.z.push_back(uniform_float(rng, zf + 0.05f, 1.0f));
        d.w.push_back(uniform_float(rng, 0.02f, 1.0f));
      }
      double sum = 0.0;
      for (double w : d.w) sum += w;
      for (double& w : d.w) w /= sum;
    }
    BlockerResult r4 = msm_blocker4(biased_moments4(d), zf);
    BlockerResult r6 = msm_blocker6(biased_moments6(d), zf);
    depth4.add(r4.depth - zf);
    shadow4.add(r4.shadow);
    depth6.add(r6.depth - zf);
    shadow6.add(r6.shadow);
    EXPECT_NEAR(r4.depth, zf, 3e-3) << "case " << i;
    EXPECT_NEAR(r4.shadow, 0.0f, 1e-4) << "case " << i;
    EXPECT_NEAR(r6.depth, zf, 0.015) << "case " << i;
    EXPECT_NEAR(r6.shadow, 0.0f, 1e-4) << "case " << i;
  }
  std::printf("[blocker, unoccluded] 4 moments: |depth - zf| p99 %.2e max %.2e, shadow max %.2e; 6 moments: "
              "|depth - zf| p99 %.2e max %.2e, shadow max %.2e\n",
              depth4.quantile(0.99), depth4.max(), shadow4.max(), depth6.quantile(0.99), depth6.max(), shadow6.max());
}

// Kneiphof: "Choosing δ1 = δ2 = ε corresponds to Eq. 7" (= JCGT Eq. (4)). Same canonical
// distribution, same sums in another order: equal to float rounding, which is
// ~eps·Σ|w z| / (ε + Σ w) <= ~1e-4 (tolerance 1e-4; it passes at 1e-5 for these seeds). The
// shadow is the same sum: bit equal. Leaving w0 out (Eq. (4) itself) or clamping the wrong
// weight changes the depth by ~w0 |zf - depth| / (ε + Σ w), typically 1e-2 and more.
// And the upper-bound variant deserves its name: with δ1 >= ε it never returns a depth further
// from the receiver than Eq. (4), and the depth grows with δ = δ1 = δ2 towards zf (same 1e-4).
TEST(Blocker, UpperVariantWithEqualDeltasIsEquation4) {
  std::mt19937_64 rng(73);
  const float eps = MSM_BLOCKER_EPSILON;
  for (int i = 0; i < 20000; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    float zf = uniform_float(rng, -1.2f, 1.2f);
    vec4 b4 = biased_moments4(d);
    Moments6 b6 = biased_moments6(d);
    float epsilon = (i % 2) ? eps : uniform_float(rng, 1e-4f, 0.1f);
    BlockerResult a4 = msm_blocker4(b4, zf, epsilon), u4 = msm_blocker4_upper(b4, zf, epsilon, epsilon);
    BlockerResult a6 = msm_blocker6(b6, zf, epsilon), u6 = msm_blocker6_upper(b6, zf, epsilon, epsilon);
    EXPECT_NEAR(u4.depth, a4.depth, 1e-4) << "case " << i;
    EXPECT_NEAR(u6.depth, a6.depth, 1e-4) << "case " << i;
    EXPECT_EQ(u4.shadow, a4.shadow);
    EXPECT_EQ(u6.shadow, a6.shadow);
    // Unclamped above (δ2 = 1): w0 itself counts, at least ε.
    EXPECT_GE(msm_blocker4_upper(b4, zf, eps, 1.0f).depth, msm_blocker4(b4, zf, eps).depth - 1e-4f);
    EXPECT_GE(msm_blocker6_upper(b6, zf, eps, 1.0f).depth, msm_blocker6(b6, zf, eps).depth - 1e-4f);
    float previous = -1e30f;
    for (float delta : {1e-3f, 1e-2f, 0.1f, 1.0f, 10.0f}) {
      float depth = msm_blocker6_upper(b6, zf, delta, delta).depth;
      EXPECT_GE(depth, previous - 1e-4f) << "case " << i << " delta " << delta;
      EXPECT_LE(depth, zf + 1e-4f);
      previous = depth;
    }
  }
}

// Agreement with Eq. (4) evaluated in double on the oracle's canonical distribution for the same
// biased float moments (JCGT Algorithm 1, m = 4 and 6; singular test off as in hamburger6_test,
// results whose own moment residual exceeds 1e-6 skipped and counted). Eq. (4) divides weight
// errors by ε + Σ w, which is ~ε = 1e-3 for nearly unoccluded fragments, so the depth is compared
// both directly and as the numerator ε zf + Σ w z = depth·(ε + Σ w), which is linear in the
// weights. The float weights differ from the oracle's as in hamburger6_test.
// Measured (seeds 78, 80; half the zf within 0.05 of a depth): 4 moments: shadow p99 9.5e-6,
// max 3.2e-3; numerator p99 5.1e-6, max 3.2e-3; depth p99 8.2e-6, max 6.8e-4. 6 moments: shadow
// p99 2.6e-5, max 2.7e-3; numerator p99 1.4e-5, max 2.1e-3; depth p99 3.1e-5, max 2.0e-3.
// Tolerances: shadow, numerator and depth p99 < 2e-4, max < 0.02.
void check_against_oracle(int m) {
  std::mt19937_64 rng(74 + m);
  const double eps = MSM_BLOCKER_EPSILON;
  ErrorStats shadow_err, numerator_err, depth_err;
  int skipped = 0, total = 20000;
  for (int i = 0; i < total; ++i) {
    test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    float zf = (i % 2) ? uniform_float(rng, -1.2f, 1.2f)
                       : float(d.z[size_t(i / 2) % d.z.size()]) + uniform_float(rng, -0.05f, 0.05f);
    std::vector<double> b;
    BlockerResult r;
    if (m == 4) {
      vec4 b4 = biased_moments4(d);
      b = {1.0, b4[0], b4[1], b4[2], b4[3]};
      r = msm_blocker4(b4, zf);
    } else {
      Moments6 b6 = biased_moments6(d);
      b = {1.0, b6.odd[0], b6.even[0], b6.odd[1], b6.even[1], b6.odd[2], b6.even[2]};
      r = msm_blocker6(b6, zf);
    }
    oracle::MomentOptions options;
    options.singular_tolerance = 0.0;
    oracle::MomentBounds ref = oracle::moment_bounds(b, zf, options);
    if (!ref.ok || ref.degenerate || ref.residual > 1e-6) {
      ++skipped;
      continue;
    }
    // support[0] = zf is not a blocker (z < zf fails), the others count where below zf.
    Reference expected = equation4(ref.support, ref.weights, zf, eps);
    ASSERT_TRUE(std::isfinite(r.depth) && std::isfinite(r.shadow)) << "case " << i;
    shadow_err.add(r.shadow - std::clamp(expected.shadow, 0.0, 1.0));
    numerator_err.add(r.depth * (eps + r.shadow) - expected.depth * (eps + expected.shadow));
    depth_err.add(r.depth - expected.depth);
  }
  std::printf("[blocker%d vs Eq. (4) on the oracle's distribution, %d skipped] shadow p99 %.2e max %.2e; "
              "numerator p99 %.2e max %.2e; depth p50 %.2e p99 %.2e max %.2e\n",
              m, skipped, shadow_err.quantile(0.99), shadow_err.max(), numerator_err.quantile(0.99),
              numerator_err.max(), depth_err.quantile(0.5), depth_err.quantile(0.99), depth_err.max());
  EXPECT_LT(skipped, total / 100);
  EXPECT_LT(shadow_err.quantile(0.99), 2e-4);
  EXPECT_LT(shadow_err.max(), 0.02);
  EXPECT_LT(numerator_err.quantile(0.99), 2e-4);
  EXPECT_LT(numerator_err.max(), 0.02);
  EXPECT_LT(depth_err.quantile(0.99), 2e-4);
  EXPECT_LT(depth_err.max(), 0.02);
  const std::string key = "math.blocker" + std::to_string(m) + "_vs_equation4.";
  const std::string what =
      "blocker search, " + std::to_string(m) + " moments, vs Eq. (4) on the oracle's distribution: ";
  test::record_figure(key + "shadow_error_p99", shadow_err.quantile(0.99),
                      {.below = 2e-4, .meaning = what + "shadow's error, p99"});
  test::record_figure(key + "shadow_error_max", shadow_err.max(),
                      {.below = 0.02, .meaning = what + "shadow's error, max"});
  test::record_figure(key + "depth_error_p99", depth_err.quantile(0.99),
                      {.below = 2e-4, .meaning = what + "blocker depth's error, p99"});
  test::record_figure(key + "depth_error_max", depth_err.max(),
                      {.below = 0.02, .meaning = what + "blocker depth's error, max"});
}

TEST(Blocker, FourMomentsEqualEquation4OnTheOraclesDistribution) { check_against_oracle(4); }
TEST(Blocker, SixMomentsEqualEquation4OnTheOraclesDistribution) { check_against_oracle(6); }

// Regression: a single occluder at z0 (or two at nearly the same depth) whose canonical
// distribution has a (nearly) double root at z0 (hamburger6_test: CoincidentRootsOfASingleDepth).
// Before the fix both Lagrange weights of the pair were 0 and blocker6 returned zf with shadow 0
// for the fully occluded receiver. Sweep: z0 at 1001 positions in [-1, 1], receivers 0.1 or more
// in front of or behind it (241 in [-1.2, 1.2]), one depth and two 3e-4 apart, plus the
// regression inputs. Occluded: depth within a fraction of zf - z0 of the occluders' mean, shadow
// ~1; unoccluded: depth ~zf, shadow ~0, for both Eq. (4) and the upper variant. Measured (also
// 9.6e6 inputs, 4001 × 1201, in brackets): occluded depth relative max 1.1e-3 (2.1e-3), upper
// variant the same, |shadow - 1| max 7.2e-5 (8.7e-5); unoccluded |depth - zf| max 4.7e-3, shadow
// max 3.9e-6 (before the fix: depth relative 1 and shadow 0 at the double roots). Tolerances: 0.01 relative and 1e-3;
// unoccluded 0.015 and 1e-4 (as UnoccludedFragmentReturnsItsOwnDepth).
TEST(Blocker, SixMomentsSingleAndCoincidentOccluders) {
  const MomentBias6 bias = msm_moment_bias6(MSM_REP6_FLOAT);
  ErrorStats depth_occ, shadow_occ, depth_up, depth_free, shadow_free;
  int nan = 0;
  auto check = [&](float z0, float z1, float zf) {
    Moments6 b = msm_apply_bias6(msm_moments6_mix(msm_moments6(z0), msm_moments6(z1), 0.37f), bias);
    float mean = 0.63f * z0 + 0.37f * z1;
    BlockerResult r = msm_blocker6(b, zf);
    BlockerResult u = msm_blocker6_upper(b, zf, MSM_BLOCKER_EPSILON, MSM_BLOCKER_EPSILON);
    nan += (std::isfinite(r.depth) && std::isfinite(r.shadow) && std::isfinite(u.depth)) ? 0 : 1;
    if (mean < zf) {
      depth_occ.add((r.depth - mean) / (zf - mean));
      depth_up.add((u.depth - mean) / (zf - mean));
      shadow_occ.add(r.shadow - 1.0f);
      EXPECT_NEAR(r.depth, mean, 0.01f * (zf - mean)) << "z0 " << z0 << " zf " << zf;
      EXPECT_NEAR(r.shadow, 1.0f, 1e-3f) << "z0 " << z0 << " zf " << zf;
    } else {
      depth_free.add(r.depth - zf);
      shadow_free.add(r.shadow);
      EXPECT_NEAR(r.depth, zf, 0.015f) << "z0 " << z0 << " zf " << zf;
      EXPECT_NEAR(r.shadow, 0.0f, 1e-4f) << "z0 " << z0 << " zf " << zf;
    }
  };
  check(-0.924f, -0.924f, 0.22f);
  check(-0.925930023f, -0.925930023f, 0.2227f);
  check(-0.965425968f, -0.965425968f, 0.100011125f);
  check(-0.917450666f, -0.917450666f, 0.157999992f);
  check(-0.954925954f, -0.954625954f, 0.108007438f);
  check(0.947024703f, 0.947324703f, -0.251999974f);
  for (int i = 0; i <= 1000; ++i) {
    float z0 = -1.0f + 2.0f * float(i) / 1000.0f + 1.234e-5f * float(i % 7);
    for (int j = 0; j <= 240; ++j) {
      float zf = -1.2f + 2.4f * float(j) / 240.0f + 3.7e-6f * float(i % 11);
      if (std::abs(zf - z0) < 0.1f) continue;
      check(z0, z0, zf);
      check(z0, z0 + 3e-4f, zf);
    }
  }
  std::printf("[blocker6, single/coincident occluders] occluded: depth relative max %.2e (upper variant, "
              "delta = eps: %.2e), |shadow - 1| max %.2e; unoccluded: |depth - zf| max %.2e, shadow max %.2e; "
              "NaN %d\n",
              depth_occ.max(), depth_up.max(), shadow_occ.max(), depth_free.max(), shadow_free.max(), nan);
  EXPECT_EQ(nan, 0);
  EXPECT_LT(depth_up.max(), 0.01);
}

} // namespace
