// The quantization transforms against the figures the papers state (2015 §4.3, JCGT §2.3-2.4,
// §5.4.3) and their defining property: b(domain) lands inside [0,1]^m.
#include "msm/msm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace {

using namespace msm;

// The determinant of an affine map given as a function, in double precision from its columns.
template <class F>
double log2_abs_det4(F f) {
  vec4 origin = f(vec4(0.0f));
  double m[4][4];
  for (int c = 0; c < 4; ++c) {
    vec4 e(0.0f);
    e[c] = 1.0f;
    vec4 col = f(e) - origin;
    for (int r = 0; r < 4; ++r) m[r][c] = col[r];
  }
  // Gaussian elimination with partial pivoting.
  double det = 1.0;
  for (int k = 0; k < 4; ++k) {
    int p = k;
    for (int r = k + 1; r < 4; ++r)
      if (std::abs(m[r][k]) > std::abs(m[p][k])) p = r;
    if (p != k) {
      for (int c = 0; c < 4; ++c) std::swap(m[k][c], m[p][c]);
      det = -det;
    }
    det *= m[k][k];
    for (int r = k + 1; r < 4; ++r) {
      double f = m[r][k] / m[k][k];
      for (int c = k; c < 4; ++c) m[r][c] -= f * m[k][c];
    }
  }
  return std::log2(std::abs(det));
}

double log2_abs_det3(mat3 m) { return std::log2(std::abs(double(determinant(dmat3(m))))); }

// The papers quote bits of entropy gained: log2|det θ| for [0,1] moments (2015), and
// log2|det Θ| + m/2 for [-1,1] moments stored directly in [0,1] (a factor 1/2 per odd moment).
TEST(Quantize, Theta4Gains12Point3Bits) { EXPECT_NEAR(log2_abs_det4(msm_theta4), 12.28, 0.01); }

TEST(Quantize, Theta4StarGains4Point21Bits) { EXPECT_NEAR(log2_abs_det4(msm_theta4_star) + 2.0, 4.21, 0.005); }

TEST(Quantize, Theta6StarGains12Point5Bits) {
  double bits = log2_abs_det3(MSM_THETA6_ODD) + log2_abs_det3(MSM_THETA6_EVEN) + 3.0;
  EXPECT_NEAR(bits, 12.51, 0.005);
}

TEST(Quantize, Theta2Gains2Bits) {
  vec2 e1 = msm_theta2(vec2(1, 0)), e2 = msm_theta2(vec2(0, 1));
  EXPECT_NEAR(std::log2(std::abs(double(e1.x) * e2.y - double(e2.x) * e1.y)), 2.0, 1e-12);
}

TEST(Quantize, UnitToSignedDepthMomentsHaveDeterminant1024) {
  EXPECT_NEAR(std::exp2(log2_abs_det4(msm_unit_to_signed_moments)), 1024.0, 1e-6);
}

TEST(Quantize, UnitToSignedMomentsMatchMomentsOfSignedDepth) {
  for (float z = 0.0f; z <= 1.0f; z += 0.0625f) {
    vec4 expected = msm_moments4(msm_signed_depth(z));
    vec4 actual = msm_unit_to_signed_moments(msm_moments4(z));
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(actual[i], expected[i], 2e-6f) << z;
  }
}

// Every transform must map the moment curve b(domain) into the representable cube; its convex
// hull (all filtered moments) then follows. Tolerance: half a 16-bit UNORM step, because an
// overshoot below that rounds to the same stored value as the clamped one. (θ4's coefficients
// are printed with 9 digits, which overshoots by 6.5e-8 in exact arithmetic; evaluating its
// entries of size ~80 in float adds up to ~3e-6.)
TEST(Quantize, TransformsMapTheMomentCurveIntoTheUnitCube) {
  const float tolerance = 0.5f / 65535.0f;
  for (int i = 0; i <= 20000; ++i) {
    float u = float(i) / 20000.0f, s = msm_signed_depth(u);
    vec4 q4 = msm_theta4(msm_moments4(u));
    vec4 q4s = msm_theta4_star(msm_moments4(s));
    vec2 q2 = msm_theta2(vec2(u, u * u));
    Moments6 q6 = msm_theta6_star(msm_moments6(s));
    for (int c = 0; c < 4; ++c) {
      EXPECT_GE(q4[c], -tolerance) << u;
      EXPECT_LE(q4[c], 1.0f + tolerance) << u;
      EXPECT_GE(q4s[c], -tolerance) << s;
      EXPECT_LE(q4s[c], 1.0f + tolerance) << s;
    }
    for (int c = 0; c < 3; ++c) {
      EXPECT_GE(q6.odd[c], -tolerance) << s;
      EXPECT_LE(q6.odd[c], 1.0f + tolerance) << s;
      EXPECT_GE(q6.even[c], -tolerance) << s;
      EXPECT_LE(q6.even[c], 1.0f + tolerance) << s;
    }
    EXPECT_GE(q2.y, -tolerance);
    EXPECT_LE(q2.y, 1.0f + tolerance);
  }
}

// The inverses are inverses: relative round-trip error at float precision (the matrices have
// condition numbers up to ~1e4 for θ4, so allow 1e-3 absolute on moments of size <= 1).
TEST(Quantize, InversesUndoTheTransforms) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 10000; ++i) {
    float u = unit(rng), s = msm_signed_depth(unit(rng));
    vec4 b = msm_moments4(u), bs = msm_moments4(s);
    vec4 r = msm_theta4_inverse(msm_theta4(b));
    vec4 rs = msm_theta4_star_inverse(msm_theta4_star(bs));
    Moments6 b6 = msm_moments6(s), r6 = msm_theta6_star_inverse(msm_theta6_star(b6));
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(r[c], b[c], 2e-4f);
      EXPECT_NEAR(rs[c], bs[c], 2e-6f);
    }
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(r6.odd[c], b6.odd[c], 2e-5f);
      EXPECT_NEAR(r6.even[c], b6.even[c], 2e-5f);
    }
    vec2 r2 = msm_theta2_inverse(msm_theta2(vec2(u, u * u)));
    EXPECT_NEAR(r2.y, u * u, 1e-6f);
  }
}

// UNORM packing rounds to nearest like Vulkan's conversion: the error is at most half a step.
TEST(Quantize, Unorm16And10RoundToNearest) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 100000; ++i) {
    vec4 v(unit(rng), unit(rng), unit(rng), unit(rng));
    vec4 q = msm_quantize_unorm16(v);
    for (int c = 0; c < 4; ++c) EXPECT_LE(std::abs(q[c] - v[c]), 0.5f / 65535.0f + 1e-7f);
    vec3 v3(v.x, v.y, v.z);
    vec3 q3 = msm_unpack_unorm10x3(msm_pack_unorm10x3(v3));
    for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(q3[c] - v3[c]), 0.5f / 1023.0f + 1e-7f);
  }
  EXPECT_EQ(msm_pack_unorm10x3(vec3(1.0f)), 0x3FFFFFFFu);
  EXPECT_EQ(msm_pack_unorm10x3(vec3(2.0f, -1.0f, 0.0f)), 1023u); // clamps
}

} // namespace
