// Prefiltered single scattering's per-texel and per-pixel math (include/msm/scattering.h and the
// resampling of include/msm/rectification.h, JCGT §5.2-5.4) against the double-precision oracle
// (JCGT Algorithm 1, src/oracle) and the true visible fraction of random depth distributions.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "msm/oracle/moment_oracle.h"
#include "msm/rectification.h"
#include "msm/scattering.h"
#include "oracle_range.h"
#include "test_distributions.h"

namespace {

using namespace msm;
using test::ErrorStats;

float uniform_float(std::mt19937_64& rng, float lo, float hi) {
  return std::uniform_real_distribution<float>(lo, hi)(rng);
}

// The true visible fraction of a view ray at depth zf: occluders at or behind it let light through
// (§5.4.2: v_l = 1 for zf <= z_l).
double visible(const test::Distribution& d, double zf) { return 1.0 - test::cdf_less(d, zf); }

// The oracle's bounds for the moments b (b0 = 1 prepended) biased by (alpha, bstar).
oracle::MomentBounds oracle_bounds(std::vector<double> b, double alpha, const std::vector<double>& bstar, double zf) {
  for (size_t j = 0; j < b.size(); ++j) b[j] = (1.0 - alpha) * b[j] + alpha * bstar[j];
  return oracle::moment_bounds(b, zf);
}

Moments6 float_moments6(const test::Distribution& d) {
  std::vector<double> m = test::power_moments(d, 6);
  return Moments6(vec3(float(m[1]), float(m[3]), float(m[5])), vec3(float(m[2]), float(m[4]), float(m[6])));
}

Moments6 store6(Moments6 b, int rep) {
  Moments6 q = msm_theta6_star(b);
  if (rep == MSM_REP6_UNORM10) return msm_quantize_unorm10(q);
  if (rep == MSM_REP6_UNORM16) return msm_quantize_unorm16(q);
  return q;
}

} // namespace

// The four-moment visibility is 1 − the oracle's bounds blended by 1 − β, on the moments the
// lookup decodes (Θ4* 16-bit and float), biased as bias.h says. As in hamburger4_test, a case that
// differs from the input vector's own bounds by more than 1e-6 is judged against the range of
// Algorithm 1 over that vector moved by up to 4 ulps per component (oracle_range.h): near-singular
// Hankel matrices are ill-conditioned in float, and hamburger4.h's D2 floor takes the light side.
// Measured (seed 5): plain difference p99 7.4e-7, max 1.9e-3; distance to the range max 1.1e-5.
TEST(PrefilteredScattering, FourMomentVisibilityEqualsTheOracle) {
  std::mt19937_64 rng(5);
  ErrorStats plain, range_err;
  for (int i = 0; i < 20000; ++i) {
    const test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    const int rep = (i % 2) ? MSM_REP_SIGNED_THETA4 : MSM_REP_SIGNED_FLOAT;
    const vec4 b = test::moments4f(d);
    const vec4 stored = rep == MSM_REP_SIGNED_THETA4 ? msm_quantize_unorm16(msm_theta4_star(b)) : b;
    const vec4 decoded = rep == MSM_REP_SIGNED_THETA4 ? msm_theta4_star_inverse(stored) : stored;
    const vec4 biased = msm_apply_bias(decoded, msm_moment_bias(rep));
    const float zf = uniform_float(rng, -0.98f, 0.98f);
    const oracle::MomentBounds o =
        oracle::moment_bounds(std::vector<double>{1.0, biased[0], biased[1], biased[2], biased[3]}, zf);
    if (!o.ok) continue; // float rounding left the moment space (edges_test counts those)
    test::BoundRange range;
    bool have_range = false;
    for (float beta : {0.0f, 0.5f, 1.0f}) {
      const double t = 1.0 - beta;
      const double shadow = 1.0 - msm_scattering_visibility4(stored, rep, zf, beta);
      const double expected = std::clamp(o.lower + t * (o.upper - o.lower), 0.0, 1.0);
      plain.add(shadow - expected);
      if (std::abs(shadow - expected) <= 1e-6) continue;
      if (!have_range) range = test::hamburger_range({biased[0], biased[1], biased[2], biased[3]}, zf, 4, 8, rng);
      have_range = true;
      const double lo = std::clamp((1.0 - t) * range.lower_min + t * range.upper_min, 0.0, 1.0);
      const double hi = std::clamp((1.0 - t) * range.lower_max + t * range.upper_max, 0.0, 1.0);
      range_err.add(range.feasible ? std::max({lo - shadow, shadow - hi, 0.0}) : 0.0);
    }
  }
  std::printf("[scattering4 vs oracle] plain p99 %.2e max %.2e; distance to the 4-ulp range max %.2e (%zu cases)\n",
              plain.quantile(0.99), plain.max(), range_err.max(), range_err.errors.size());
  EXPECT_LT(plain.quantile(0.99), 1e-4);
  EXPECT_LT(range_err.max(), 5e-4);
}

// Six moments, every storage of §5.4.3 (Θ6* in 10, 16 bits and float), against the oracle at the
// decoded moments biased in double. Measured (seed 6): p99 9.0e-6, max 2.9e-3 (hamburger6.h's
// float solve and its float bias).
TEST(PrefilteredScattering, SixMomentVisibilityEqualsTheOracle) {
  std::mt19937_64 rng(6);
  ErrorStats err;
  int failed = 0;
  for (int i = 0; i < 15000; ++i) {
    const test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    const int rep = MSM_REP6_UNORM10 + i % 3;
    const Moments6 stored = store6(float_moments6(d), rep);
    const Moments6 m = msm_theta6_star_inverse(stored);
    const MomentBias6 bias = msm_moment_bias6(rep);
    const float zf = uniform_float(rng, -0.98f, 0.98f);
    const oracle::MomentBounds o =
        oracle_bounds({1.0, m.odd[0], m.even[0], m.odd[1], m.even[1], m.odd[2], m.even[2]}, bias.alpha,
                      {1.0, 0.0, bias.bstar.even[0], 0.0, bias.bstar.even[1], 0.0, bias.bstar.even[2]}, zf);
    if (!o.ok) {
      ++failed; // the 10-bit rounding may leave a vector the bias does not bring back: counted
      continue;
    }
    for (float beta : {0.0f, 0.5f, 1.0f}) {
      const double expected = 1.0 - std::clamp(o.lower + (1.0 - beta) * (o.upper - o.lower), 0.0, 1.0);
      err.add(msm_scattering_visibility6(stored, rep, zf, beta) - expected);
    }
  }
  std::printf("[scattering6 vs oracle] p99 %.2e max %.2e, %d of 15000 outside the moment space\n", err.quantile(0.99),
              err.max(), failed);
  EXPECT_EQ(failed, 0);
  EXPECT_LT(err.quantile(0.99), 1e-3);
  EXPECT_LT(err.max(), 2e-2);
}

// β = 0 and β = 1 bracket the true visible fraction (float storage, where the bias is tiny):
// vis(β = 0) <= Z(z > zf) <= Z(z >= zf) <= vis(β = 1), up to the bias and the float solve.
TEST(PrefilteredScattering, BoundsBracketTheTrueVisibleFraction) {
  std::mt19937_64 rng(7);
  double worst4 = 0.0, worst6 = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const test::Distribution d = test::random_distribution(rng, -1.0, 1.0);
    const float zf = (i % 2) ? uniform_float(rng, -0.98f, 0.98f)
                             : float(d.z[size_t(i / 2) % d.z.size()]) + uniform_float(rng, -0.02f, 0.02f);
    const double above = 1.0 - test::cdf_less_equal(d, zf), at_or_above = visible(d, zf);
    const vec4 b4 = test::moments4f(d);
    worst4 = std::max(worst4, msm_scattering_visibility4(b4, MSM_REP_SIGNED_FLOAT, zf, 0.0f) - above);
    worst4 = std::max(worst4, at_or_above - msm_scattering_visibility4(b4, MSM_REP_SIGNED_FLOAT, zf, 1.0f));
    const Moments6 s6 = store6(float_moments6(d), MSM_REP6_FLOAT);
    worst6 = std::max(worst6, msm_scattering_visibility6(s6, MSM_REP6_FLOAT, zf, 0.0f) - above);
    worst6 = std::max(worst6, at_or_above - msm_scattering_visibility6(s6, MSM_REP6_FLOAT, zf, 1.0f));
  }
  std::printf("[scattering bracket] worst violation four %.2e six %.2e\n", worst4, worst6);
  EXPECT_LT(worst4, 2e-3);
  EXPECT_LT(worst6, 2e-3);
}

// §5.4: along a view ray many surfaces shadow it, and six moments represent those distributions
// better than four. Mean |visibility(β = ½) − truth| over 4-8 random depths, float storage.
TEST(PrefilteredScattering, SixMomentsBeatFourOnComplexDistributions) {
  std::mt19937_64 rng(8);
  double e4 = 0.0, e6 = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const test::Distribution d = test::random_diracs(rng, 4 + i % 5, -0.9, 0.9);
    const float zf = uniform_float(rng, -0.95f, 0.95f);
    const double truth = visible(d, zf);
    e4 += std::abs(msm_scattering_visibility4(test::moments4f(d), MSM_REP_SIGNED_FLOAT, zf, 0.5f) - truth);
    e6 += std::abs(msm_scattering_visibility6(store6(float_moments6(d), MSM_REP6_FLOAT), MSM_REP6_FLOAT, zf, 0.5f) -
                   truth);
  }
  std::printf("[scattering complex] mean error four %.4f six %.4f\n", e4 / n, e6 / n);
  EXPECT_LT(e6, 0.8 * e4);
}

TEST(PrefilteredScattering, AdaptiveBetaUnderestimatesIntoTheLight) {
  const vec3 l = normalize(vec3(0.3f, 0.8f, -0.2f));
  EXPECT_NEAR(msm_scattering_beta_adaptive(l, l), 0.0f, 1e-6f);  // looking into the light
  EXPECT_NEAR(msm_scattering_beta_adaptive(l, -l), 1.0f, 1e-6f); // looking away from it
  const vec3 across = normalize(cross(l, vec3(0.0f, 0.0f, 1.0f)));
  EXPECT_NEAR(msm_scattering_beta_adaptive(l, across), 0.5f, 1e-6f);
  // Near the epipole it varies slowly: quadratically in the angle.
  const vec3 near_epipole = normalize(l + 0.01f * across);
  EXPECT_LT(msm_scattering_beta_adaptive(l, near_epipole), 1e-4f);
  // A visible fraction of an occluder exactly at the ray's depth: β = 0 reads it as shadow.
  const vec4 b = msm_moments4(0.2f);
  EXPECT_LT(msm_scattering_visibility4(b, MSM_REP_SIGNED_FLOAT, 0.2f, 0.0f), 0.01f);
  EXPECT_GT(msm_scattering_visibility4(b, MSM_REP_SIGNED_FLOAT, 0.2f, 1.0f), 0.99f);
}

// The proportional β against hand-computed answers: the undecided weight w0 = upper − lower is
// shared as the rest is, so the visible fraction is the surely lit mass over the decided mass,
// (1 − upper) / ((1 − upper) + lower); towards the epipole it ramps to 0 (cone 36.87°, where
// (1 − cos θ) / 2 = 0.1).
TEST(PrefilteredScattering, ProportionalBetaSharesTheUndecidedWeightAsTheRest) {
  const vec3 l = normalize(vec3(0.3f, 0.8f, -0.2f));
  const vec3 across = normalize(cross(l, vec3(0.0f, 0.0f, 1.0f)));
  // Shadow bounds (0.2, 0.6): surely lit 0.4, surely shadowed 0.2, β = 2/3, visible 0.4 / 0.6.
  EXPECT_NEAR(msm_scattering_beta_mass_ratio(vec2(0.2f, 0.6f)), 2.0f / 3.0f, 1e-6f);
  // β of the bounds for a view direction (from the camera outwards).
  const auto beta = [&](vec2 bounds, vec3 view) {
    return msm_scattering_beta_proportional(bounds, msm_scattering_beta_adaptive(l, view));
  };
  EXPECT_NEAR(beta(vec2(0.2f, 0.6f), across), 2.0f / 3.0f, 1e-6f);
  EXPECT_NEAR(msm_scattering_visibility_between(vec2(0.2f, 0.6f), 2.0f / 3.0f), 2.0f / 3.0f, 1e-6f);
  // Nothing surely shadowed: the upper bound of the visible fraction; nothing surely lit: the
  // lower; nothing decided: ½.
  EXPECT_NEAR(msm_scattering_beta_mass_ratio(vec2(0.0f, 0.3f)), 1.0f, 1e-6f);
  EXPECT_NEAR(msm_scattering_beta_mass_ratio(vec2(0.4f, 1.0f)), 0.0f, 1e-5f);
  EXPECT_EQ(msm_scattering_beta_mass_ratio(vec2(0.0f, 1.0f)), 0.5f);
  // The visible fraction is lit / (lit + shadowed) for any bounds (a sweep).
  for (float lower = 0.0f; lower <= 1.0f; lower += 0.125f)
    for (float upper = lower; upper <= 1.0f; upper += 0.125f) {
      const float lit = 1.0f - upper, decided = lit + lower;
      if (decided <= 0.0f) continue;
      const float visible = msm_scattering_visibility_between(vec2(lower, upper), beta(vec2(lower, upper), across));
      EXPECT_NEAR(visible, lit / decided, 1e-5f) << lower << ", " << upper;
    }
  // The epipole: looking into the light β = 0 whatever the bounds; 20° off it the ramp at
  // a = (1 − cos 20°) / 2 = 0.0302: x = 0.302, x (2 − x) = 0.513; from 36.87° on, the ratio alone.
  EXPECT_EQ(msm_scattering_beta_proportional(vec2(0.0f, 0.3f), msm_scattering_beta_adaptive(l, l)), 0.0f);
  const auto towards = [&](float degrees) {
    const float t = glm::radians(degrees);
    return std::cos(t) * l + std::sin(t) * across;
  };
  const float a20 = 0.5f * (1.0f - std::cos(glm::radians(20.0f))), x20 = a20 / MSM_SCATTERING_EPIPOLE_CONE;
  EXPECT_NEAR(beta(vec2(0.0f, 0.3f), towards(20.0f)), x20 * (2.0f - x20), 1e-5f);
  EXPECT_NEAR(x20 * (2.0f - x20), 0.513f, 1e-3f);
  EXPECT_NEAR(beta(vec2(0.0f, 0.3f), towards(37.0f)), 1.0f, 1e-6f);
  EXPECT_LT(beta(vec2(0.0f, 0.3f), towards(36.0f)), 0.999f);
}

// Algorithm 2 then the map of §5.1.1: a filtered texel over two surfaces comes back as those two
// surfaces' rectified depths with their weights (exact for two depths: b0..b3 determine them).
// Rectified depths computed independently in double.
TEST(PrefilteredScattering, FilteredResamplingRecoversTwoSurfaces) {
  std::mt19937_64 rng(9);
  RectifiedBounds b{};
  b.r_max = 40.0f, b.phi_min = 0.0f, b.phi_span = MSM_TWO_PI, b.theta_min = 0.2f, b.theta_max = 2.9f;
  const vec2 depth_to_z(30.0f, 5.0f); // map depth [-1,1] -> z in [-25, 35] along the light
  ErrorStats depth_err, weight_err;
  for (int i = 0; i < 5000; ++i) {
    const double z1 = uniform_float(rng, -1.0f, 0.4f), z2 = z1 + uniform_float(rng, 0.1f, 0.6f);
    const double w2 = uniform_float(rng, 0.1f, 0.9f);
    const float r = uniform_float(rng, 0.5f, 40.0f);
    test::Distribution d{{z1, z2}, {1.0 - w2, w2}};
    const TwoDepths got = msm_rectified_two_depths(b, r, depth_to_z, test::moments4f(d));
    for (int k = 0; k < 2; ++k) {
      const double z = depth_to_z.x * (k ? z2 : z1) + depth_to_z.y;
      const double theta = std::atan2(double(r), z);
      const double unit = std::clamp((b.theta_max - theta) / (b.theta_max - b.theta_min), 0.0, 1.0);
      depth_err.add(got.z[k] - (2.0 * unit - 1.0));
    }
    weight_err.add(got.w.y - w2);
    weight_err.add(got.w.x + got.w.y - 1.0);
    // Its moments are the two atoms' moments.
    const vec4 m = msm_rectified_moments4(got);
    EXPECT_NEAR(m[0], got.w.x * got.z.x + got.w.y * got.z.y, 1e-5f);
  }
  std::printf("[resampling] depth p99 %.2e max %.2e, weight max %.2e\n", depth_err.quantile(0.99), depth_err.max(),
              weight_err.max());
  EXPECT_LT(depth_err.max(), 5e-3);
  EXPECT_LT(weight_err.max(), 5e-3);
  // Zero variance (one surface, or no occluder: the cleared depth): that depth, weight 1.
  const TwoDepths one = msm_rectified_two_depths(b, 10.0f, depth_to_z, msm_moments4(0.3f));
  const TwoDepths plain = msm_rectified_one_depth(b, 10.0f, depth_to_z, 0.3f);
  EXPECT_NEAR(one.z.x, plain.z.x, 1e-5f);
  EXPECT_NEAR(one.w.x, 1.0f, 1e-6f);
  EXPECT_EQ(plain.w.y, 0.0f);
  // Six moments and CSM of the same atoms.
  const Moments6 m6 = msm_rectified_moments6(plain);
  EXPECT_NEAR(m6.even[2], std::pow(plain.z.x, 6.0f), 1e-6f);
  const CsmMoments c = msm_rectified_csm(plain, 16);
  EXPECT_NEAR(msm_csm_texel(c, 0)[0], std::sin(MSM_PI * msm_unit_depth(plain.z.x)), 1e-5f);
}

// Klehm et al.'s CSM reconstruction for scattering: a lone occluder at unit depth z0. Rays well in
// front of it are lit and rays well behind it shadowed, up to the ringing of the truncated
// series; at the occluder's depth it reads ½. Measured: within 0.06 beyond 0.1 of z0.
TEST(PrefilteredScattering, ConvolutionShadowMapBaseline) {
  const CsmParams p = msm_csm_scattering_params();
  EXPECT_EQ(p.terms, 16); // 32 coefficients
  double worst = 0.0;
  for (float z0 : {0.3f, 0.5f, 0.7f}) {
    CsmMoments m = msm_csm_moments(z0, p.terms);
    // 8-bit storage, as Klehm et al. store it.
    for (int t = 0; t < MSM_CSM_MAX_TEXELS; ++t) {
      vec4 q = msm_csm_from_unorm(vec4(glm::round(msm_csm_to_unorm(msm_csm_texel(m, t)) * 255.0f) / 255.0f));
      if (t < 4)
        m.lo[t] = q;
      else
        m.hi[t - 4] = q;
    }
    for (float zf = 0.05f; zf < 0.95f; zf += 0.01f) {
      if (std::abs(zf - z0) < 0.1f) continue;
      worst = std::max(worst, std::abs(msm_scattering_visibility_csm(m, zf, p) - (zf < z0 ? 1.0 : 0.0)));
    }
    EXPECT_NEAR(msm_scattering_visibility_csm(m, z0, p), 0.5f, 0.05f);
  }
  std::printf("[csm scattering] worst error beyond 0.1 of the occluder %.3f\n", worst);
  EXPECT_LT(worst, 0.1);
}

// Ray marching: the weights integrate the transmittance exactly; jittered samples of a step
// visibility average to its integral.
TEST(PrefilteredScattering, RayMarchingWeights) {
  for (int n : {32, 128}) {
    const float sigma = 0.07f, s = 40.0f, lit_until = 13.3f;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += msm_ray_march_weight(sigma, s, n, i);
    EXPECT_NEAR(sum, msm_transmittance_integral(sigma, 0.0f, s), 1e-5 * sum);
    double mean = 0.0;
    const int jitters = 256;
    for (int k = 0; k < jitters; ++k) {
      const float jitter = (k + 0.5f) / jitters;
      double acc = 0.0;
      for (int i = 0; i < n; ++i)
        acc += msm_ray_march_weight(sigma, s, n, i) * (msm_ray_march_distance(s, n, i, jitter) < lit_until ? 1.0 : 0.0);
      mean += acc / sum / jitters;
    }
    // The average over jitters is the integral of the step against the per-segment weights.
    const double exact = msm_transmittance_integral(sigma, 0.0f, lit_until) / sum;
    EXPECT_NEAR(mean, exact, 0.5 * std::exp(-sigma * lit_until) * s / n / sum + 1e-4) << n;
  }
}

// Garbage in the map (NaN, inf, a texel never written) or a ray depth out of range: a visible
// fraction in [0, 1], never NaN.
TEST(PrefilteredScattering, BadInputGivesAFiniteVisibleFraction) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float zfs[] = {-1.0f, 0.0f, 1.0f, 2.0f, nan, inf, -inf};
  const vec4 bad4[] = {vec4(nan), vec4(inf), vec4(0.0f), vec4(1.0f), vec4(-inf, 0.5f, nan, 2.0f)};
  for (float zf : zfs)
    for (float beta : {0.0f, 0.5f, 1.0f, nan}) {
      for (const vec4& b : bad4)
        for (int rep : {MSM_REP_SIGNED_THETA4, MSM_REP_SIGNED_FLOAT}) {
          const float v = msm_scattering_visibility4(b, rep, zf, beta);
          EXPECT_TRUE(v >= 0.0f && v <= 1.0f) << v;
        }
      for (const vec4& b : bad4)
        for (int rep : {MSM_REP6_UNORM10, MSM_REP6_UNORM16, MSM_REP6_FLOAT}) {
          const float v = msm_scattering_visibility6(Moments6(vec3(b), vec3(b[3], b[0], b[1])), rep, zf, beta);
          EXPECT_TRUE(v >= 0.0f && v <= 1.0f) << v;
        }
    }
}
