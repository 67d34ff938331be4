// Storage robustness: millions of random filtered moment vectors, degenerate ones included, go
// through each representation's store -> load -> bias -> reconstruction. Every result must be
// finite and inside [0,1] (a NaN or out-of-range shadow is a visible pixel error), and the
// error of each representation against unquantized float moments is measured and printed.
#include "msm/hamburger6.h"
#include "msm/msm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace {

using namespace msm;

// A kernel's depths in [-1,1]: random mixtures, or one of the degenerate cases of the issue:
// one depth, two equal depths, depths at ±1, all depths clamped to the ends.
struct Kernel {
  float z[4];
  float w[4];
  int n;
};

Kernel random_kernel(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Kernel k{};
  int kind = int(u(rng) * 8.0f);
  k.n = 1 + int(u(rng) * 4.0f) % 4;
  for (int i = 0; i < 4; ++i) {
    k.z[i] = 2.0f * u(rng) - 1.0f;
    k.w[i] = 0.01f + u(rng);
  }
  if (kind == 0) k.n = 1;                       // one depth
  if (kind == 1) k.n = 2, k.z[1] = k.z[0];      // two equal depths
  if (kind == 2) k.z[0] = -1.0f, k.z[1] = 1.0f; // depths at ±1
  if (kind == 3)
    for (int i = 0; i < 4; ++i) k.z[i] = u(rng) < 0.5f ? -1.0f : 1.0f; // all clamped
  if (kind == 4) k.n = 2, k.z[1] = k.z[0] + 1e-3f * u(rng);            // short range
  float sum = 0.0f;
  for (int i = 0; i < k.n; ++i) sum += k.w[i];
  for (int i = 0; i < k.n; ++i) k.w[i] /= sum;
  return k;
}

vec4 filtered4(const Kernel& k, bool unit) {
  vec4 b(0.0f);
  for (int i = 0; i < k.n; ++i) b += k.w[i] * msm_moments4(unit ? msm_unit_depth(k.z[i]) : k.z[i]);
  return b;
}

Moments6 filtered6(const Kernel& k) {
  Moments6 b = Moments6(vec3(0.0f), vec3(0.0f));
  for (int i = 0; i < k.n; ++i) b = msm_moments6_scale_add(b, msm_moments6(k.z[i]), k.w[i]);
  return b;
}

struct Stats {
  const char* name;
  double sum = 0, max = 0;
  long count = 0, bad = 0;
  void add(float value, float reference) {
    if (!(std::isfinite(value) && value >= 0.0f && value <= 1.0f)) ++bad;
    double e = std::abs(double(value) - reference);
    sum += e;
    max = std::max(max, e);
    ++count;
  }
  void report() const { std::printf("| %-34s | %9.2e | %9.2e | %ld |\n", name, sum / count, max, bad); }
};

constexpr int kSamples = 1000000;

TEST(Robustness, EveryRepresentationStaysFiniteAndInRange) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Stats theta4{"4MSM [0,1], θ4, 16-bit"}, theta4s{"4MSM [-1,1], Θ4*, 16-bit"}, hausdorff{"Hausdorff [0,1], θ4, 16-bit"},
      nl64{"NL 64-bit (HPG)"}, nl32{"NL 32-bit (HPG)"}, six16{"6MSM Θ6*, 16-bit"}, six10{"6MSM Θ6*, 10-bit"},
      unitf{"4MSM [0,1] float (reference: self)"};
  for (int i = 0; i < kSamples; ++i) {
    Kernel k = random_kernel(rng);
    float zf = 2.2f * u(rng) - 1.1f, zu = msm_unit_depth(zf);
    vec4 bu = filtered4(k, true), bs = filtered4(k, false);
    // Reference: the same reconstruction on unquantized float moments.
    float ref_unit = msm_hamburger4_lower(msm_apply_bias(bu, msm_moment_bias(MSM_REP_UNIT_FLOAT)), zu);
    float ref_signed = msm_hamburger4_lower(msm_apply_bias(bs, msm_moment_bias(MSM_REP_SIGNED_FLOAT)), zf);
    unitf.add(ref_unit, ref_unit);

    // As the technique reads it: biased, D2 raised to the representation's floor (bias.h).
    vec4 lu = msm_raise_d2(
        msm_apply_bias(msm_theta4_inverse(msm_quantize_unorm16(msm_theta4(bu))), msm_moment_bias(MSM_REP_UNIT_THETA4)),
        MSM_MIN_D2_UNIT_16BIT);
    theta4.add(msm_hamburger4_lower(lu, zu), ref_unit);
    hausdorff.add(msm_hausdorff4_lower(lu, zu, 0.0f, 1.0f),
                  msm_hausdorff4_lower(msm_apply_bias(bu, msm_moment_bias(MSM_REP_UNIT_FLOAT)), zu, 0.0f, 1.0f));
    vec4 ls = msm_apply_bias(msm_theta4_star_inverse(msm_quantize_unorm16(msm_theta4_star(bs))),
                             msm_moment_bias(MSM_REP_SIGNED_THETA4));
    theta4s.add(msm_hamburger4_lower(ls, zf), ref_signed);
    NonLinearMoments nl = msm_nl_from_filtered(bs);
    nl64.add(msm_nl_shadow(msm_nl_quantize64(nl), zf), ref_signed);
    nl32.add(msm_nl_shadow(msm_nl_quantize32(nl), zf), ref_signed);

    Moments6 b6 = filtered6(k);
    float ref6 = msm_hamburger6_lower(msm_apply_bias6(b6, msm_moment_bias6(MSM_REP6_FLOAT)), zf);
    Moments6 l16 = msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm16(msm_theta6_star(b6))),
                                   msm_moment_bias6(MSM_REP6_UNORM16));
    six16.add(msm_hamburger6_lower(l16, zf), ref6);
    Moments6 l10 = msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm10(msm_theta6_star(b6))),
                                   msm_moment_bias6(MSM_REP6_UNORM10));
    six10.add(msm_hamburger6_lower(l10, zf), ref6);
  }
  std::printf("\n| representation (vs float, same reconstruction) | mean abs error | max abs error | not finite or "
              "outside [0,1] |\n|---|---|---|---|\n");
  for (const Stats* s : {&unitf, &theta4, &hausdorff, &theta4s, &nl64, &nl32, &six16, &six10}) {
    s->report();
    EXPECT_EQ(s->bad, 0) << s->name;
    EXPECT_EQ(s->count, kSamples);
  }
}

} // namespace
