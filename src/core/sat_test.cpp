// Integer summed-area tables (include/msm/sat.h, JCGT §4.2, §4.4): quantization, exact rectangle
// sums despite wrap-around for every rectangle of up to n_t texels, detectable failure beyond n_t,
// the nine-region query of fractional filter regions against the exact box-filter integral, and
// the six-moment split. References are double-precision sums of the quantized integers (exact:
// every partial sum here is below 2^53) and 64-bit integer running sums; none uses sat.h's queries.
#include "msm/quantize.h"
#include "msm/sat.h"
#include "test_tables.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

namespace {

using namespace msm;
using test::build;
using test::Table;

// A random Θ4* moment map: Θ4* of the moments of a random depth per texel (random in [-1,1]),
// with every `ones_every`-th texel at q = (1,1,1,1), the largest value, so sums wrap often.
std::vector<vec4> random_map(std::mt19937_64& rng, int width, int height, int ones_every) {
  std::uniform_real_distribution<float> depth(-1.0f, 1.0f);
  std::vector<vec4> map(size_t(width) * size_t(height));
  for (size_t i = 0; i < map.size(); ++i)
    map[i] = (ones_every > 0 && i % size_t(ones_every) == 0) ? vec4(1.0f) : msm_theta4_star(msm_moments4(depth(rng)));
  return map;
}

// Double-precision prefix sums of the quantized values (exact: totals < 2^53), per channel.
struct Exact {
  int width = 0;
  std::vector<double> p[4]; // (width + 1) × (height + 1), p[c][(y + 1)(width + 1) + x + 1]
  double sum(int c, int x0, int y0, int x1, int y1) const {
    auto P = [&](int x, int y) { return p[c][size_t(y + 1) * size_t(width + 1) + size_t(x + 1)]; };
    return P(x1, y1) - P(x0 - 1, y1) - P(x1, y0 - 1) + P(x0 - 1, y0 - 1);
  }
};
Exact exact_prefix(const Table& t) {
  Exact e;
  e.width = t.width;
  for (int c = 0; c < 4; ++c) {
    e.p[c].assign(size_t(t.width + 1) * size_t(t.height + 1), 0.0);
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x)
        e.p[c][size_t(y + 1) * size_t(t.width + 1) + size_t(x + 1)] =
            double(t.q[size_t(y) * size_t(t.width) + size_t(x)][c]) +
            e.p[c][size_t(y) * size_t(t.width + 1) + size_t(x + 1)] +
            e.p[c][size_t(y + 1) * size_t(t.width + 1) + size_t(x)] -
            e.p[c][size_t(y) * size_t(t.width + 1) + size_t(x)];
  }
  return e;
}

uvec4 query(const Table& t, int x0, int y0, int x1, int y1) { return t.sum(x0, y0, x1, y1); }

// The scale s = floor((2^32 - 1) / n_t) keeps n_t texels at the largest value within 32 bits; the
// scale as JCGT writes it, rounded, does not for about half of all n_t (e.g. 27² = 729:
// (2^32 - 1) / 729 = 5891587.51, so 729 · 5891588 = 2^32 + 356). Quantization is round-to-nearest
// within one step for n_t >= 256 (q · float(s) is exact to 2^-24 relative, s < 2^24), clamps to
// [0, s], maps NaN to 0, and never converts a float >= 2^32 (n_t = 1).
TEST(Sat, ScaleAndQuantization) {
  const uint64_t max32 = 0xFFFFFFFFull;
  EXPECT_EQ(msm_sat_scale(729), uint(max32 / 729));
  EXPECT_EQ(msm_sat_scale(729), 5891587u);
  EXPECT_NEAR(std::log2(double(msm_sat_scale(784))), 22.4, 0.05); // JCGT: 22.4 bits for 28²
  int rounded_overflows = 0;
  for (int nt = 1; nt <= 4096; ++nt) {
    uint s = msm_sat_scale(nt);
    EXPECT_LE(uint64_t(nt) * s, max32) << nt;
    EXPECT_LE(msm_sat_quantize(vec4(1.0f), s)[3], s) << nt;
    rounded_overflows += uint64_t(nt) * uint64_t(std::llround(double(max32) / nt)) > max32 ? 1 : 0;
  }
  std::printf("[sat] n_t in 1..4096 where the rounded scale (2^32-1)/n_t would overflow: %d\n", rounded_overflows);
  EXPECT_GT(rounded_overflows, 1000);
  EXPECT_GT(uint64_t(729) * 5891588ull, max32);

  const uint s = msm_sat_scale(1089);
  EXPECT_EQ(msm_sat_quantize(vec4(0.0f, 1.0f, -0.5f, 2.0f), s), uvec4(0u, s, 0u, s));
  EXPECT_EQ(msm_sat_quantize(vec4(std::numeric_limits<float>::quiet_NaN()), s), uvec4(0u));
  EXPECT_EQ(msm_sat_quantize(vec4(0.5f), 3u), uvec4(2u)); // 1.5 rounds to even
  EXPECT_EQ(msm_sat_quantize(vec4(0.5f), 5u), uvec4(2u)); // 2.5 rounds to even
  uvec4 one = msm_sat_quantize(vec4(1.0f), msm_sat_scale(1));
  EXPECT_EQ(one[0], 4294967040u); // the largest float below 2^32: clamped before the conversion
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  double worst = 0.0;
  for (int nt : {256, 729, 1089, 4096, 1 << 20}) {
    uint sc = msm_sat_scale(nt);
    for (int i = 0; i < 100000; ++i) {
      float q = unit(rng);
      double error = std::abs(double(msm_sat_quantize(vec4(q), sc)[0]) - double(q) * double(sc));
      worst = std::max(worst, error);
      ASSERT_LE(error, 1.0) << "n_t " << nt << " q " << q;
    }
  }
  std::printf("[sat] |Q - q s| max %.3f (n_t >= 256)\n", worst);
  // Dequantization inverts within half a step.
  for (int i = 0; i < 1000; ++i) {
    vec4 q(unit(rng), unit(rng), unit(rng), unit(rng));
    vec4 back = msm_sat_dequantize(msm_sat_quantize(q, s), s);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(back[c], q[c], 0.5 / s + 1e-7);
  }
}

// Every rectangle of up to n_t texels of a 64² table (n_t = 27² and 33²; 3.3 and 3.8 million
// rectangles, corners on every border) is summed exactly, although most of the table's running
// sums have wrapped around 2^32. A double-precision table of the same integers is the reference;
// it is itself checked against direct summation on a sample of rectangles.
TEST(Sat, EveryRectangleUpToNtTexelsIsExact) {
  const int size = 64;
  std::mt19937_64 rng(12);
  for (int width_limit : {27, 33}) {
    const int nt = width_limit * width_limit;
    const uint scale = msm_sat_scale(nt);
    std::vector<vec4> map = random_map(rng, size, size, 2);
    Table t = build(map, size, size, scale);
    Exact e = exact_prefix(t);
    // Table values whose true running sum is 2^32 or more (stored wrapped), in any channel.
    int wrapped = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        bool any = false;
        for (int c = 0; c < 4; ++c) any = any || e.sum(c, 0, 0, x, y) >= 4294967296.0;
        wrapped += any ? 1 : 0;
      }
    const double wraps = e.sum(3, 0, 0, size - 1, size - 1) / 4294967296.0;
    EXPECT_GT(wrapped, size * size / 4) << "the test needs running sums that wrap around";
    // The double table against direct sums.
    std::uniform_int_distribution<int> coord(0, size - 1);
    for (int i = 0; i < 2000; ++i) {
      int x0 = coord(rng), x1 = coord(rng), y0 = coord(rng), y1 = coord(rng);
      if (x0 > x1) std::swap(x0, x1);
      if (y0 > y1) std::swap(y0, y1);
      for (int c = 0; c < 4; ++c) {
        double direct = 0.0;
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) direct += double(t.q[size_t(y) * size + size_t(x)][c]);
        ASSERT_EQ(direct, e.sum(c, x0, y0, x1, y1));
      }
    }
    long long rectangles = 0, mismatches = 0, at_limit = 0;
    for (int y0 = 0; y0 < size; ++y0)
      for (int y1 = y0; y1 < size; ++y1)
        for (int x0 = 0; x0 < size; ++x0)
          for (int x1 = x0; x1 < size && (x1 - x0 + 1) * (y1 - y0 + 1) <= nt; ++x1) {
            uvec4 sum = query(t, x0, y0, x1, y1);
            for (int c = 0; c < 4; ++c) mismatches += double(sum[c]) != e.sum(c, x0, y0, x1, y1) ? 1 : 0;
            at_limit += (x1 - x0 + 1) * (y1 - y0 + 1) == nt ? 1 : 0;
            ++rectangles;
          }
    std::printf("[sat] 64x64, n_t = %d: %lld rectangles of <= n_t texels (%lld of exactly n_t), %d of 4096 table "
                "values wrapped (the total is %.1f × 2^32), mismatches %lld\n",
                nt, rectangles, at_limit, wrapped, wraps, mismatches);
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(at_limit, 0);
    // The averages are the sums over area · s, in [0,1].
    vec4 average = msm_sat_rect_average(query(t, 3, 4, 3 + width_limit - 1, 4 + width_limit - 1), nt, scale);
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(average[c], e.sum(c, 3, 4, 3 + width_limit - 1, 4 + width_limit - 1) / (double(nt) * scale), 1e-6);
  }
}

// Beyond n_t texels the true sum can exceed 2^32 - 1 and the query returns it modulo 2^32: with
// every texel at the largest value, n_t + 1 texels already wrap; with random moments, most large
// rectangles come back wrong. (So EveryRectangleUpToNtTexelsIsExact could fail: it would, on any
// rectangle beyond the limit.)
TEST(Sat, RectanglesBeyondNtAreDetectablyWrong) {
  const int size = 64, nt = 27 * 27;
  const uint scale = msm_sat_scale(nt);
  Table ones = build(std::vector<vec4>(size_t(size * size), vec4(1.0f)), size, size, scale);
  // 27 × 27 = n_t: exact; 27 × 28 and 28 × 28: wrapped.
  EXPECT_EQ(double(query(ones, 0, 0, 26, 26)[0]), double(nt) * scale);
  for (int h : {28, 29, 40}) {
    double truth = double(27 * h) * scale;
    uvec4 got = query(ones, 5, 7, 5 + 26, 7 + h - 1);
    EXPECT_NE(double(got[0]), truth) << "27 x " << h;
    EXPECT_EQ(double(got[0]), std::fmod(truth, 4294967296.0)) << "27 x " << h << ": the sum modulo 2^32";
  }
  std::mt19937_64 rng(13);
  Table t = build(random_map(rng, size, size, 0), size, size, scale);
  Exact e = exact_prefix(t);
  long long large = 0, wrong = 0;
  for (int y0 = 0; y0 < size; y0 += 2)
    for (int x0 = 0; x0 < size; x0 += 2)
      for (int y1 = y0; y1 < size; ++y1)
        for (int x1 = x0; x1 < size; ++x1) {
          if ((x1 - x0 + 1) * (y1 - y0 + 1) <= 4 * nt) continue;
          ++large;
          uvec4 sum = query(t, x0, y0, x1, y1);
          bool any = false;
          for (int c = 0; c < 4; ++c) any = any || double(sum[c]) != e.sum(c, x0, y0, x1, y1);
          wrong += any ? 1 : 0;
        }
  std::printf("[sat] random moments, rectangles of > 4 n_t texels: %lld of %lld wrong\n", wrong, large);
  EXPECT_GT(large, 1000);
  EXPECT_GT(double(wrong), 0.95 * double(large));
}

// The exact integral of the quantized moment map (piecewise constant, texel i on [i, i + 1)) over
// [lo, hi], divided by the area, in double.
dvec4 box_filter(const Table& t, vec2 lo, vec2 hi, uint scale) {
  dvec4 sum(0.0);
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      double cx = std::max(0.0, std::min(double(hi.x), x + 1.0) - std::max(double(lo.x), double(x)));
      double cy = std::max(0.0, std::min(double(hi.y), y + 1.0) - std::max(double(lo.y), double(y)));
      if (cx > 0.0 && cy > 0.0) sum += cx * cy * dvec4(t.q[size_t(y) * size_t(t.width) + size_t(x)]);
    }
  return sum / ((double(hi.x) - lo.x) * (double(hi.y) - lo.y) * double(scale));
}

vec4 nine_region(const Table& t, vec2 lo, vec2 hi, uint scale) {
  return t.filter_average(msm_sat_filter(lo, hi), scale);
}

// JCGT §4.4, Fig. 7b: the nine-region query equals the exact box filter with fractional coverage:
// random regions of widths 0.01 to W - 1 texels (W = 27, n_t = W²) anywhere in a 61 × 47 map
// (borders at 0 and at the map's edges, integral and one-texel regions included), where the
// running sums wrap. Error: float conversion and weighting of nine sums (each ~6e-8 relative):
// measured max 2.0e-7 (seed 14); tolerance 2e-6. Also: every read lies in [-1, size - 1] and the
// touched block holds at most W × W texels.
TEST(Sat, NineRegionQueryIsTheExactBoxFilter) {
  const int w = 61, h = 47, W = 27;
  const uint scale = msm_sat_scale(W * W);
  std::mt19937_64 rng(14);
  Table t = build(random_map(rng, w, h, 3), w, h, scale);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  double worst = 0.0;
  auto check = [&](vec2 lo, vec2 hi) {
    SatFilter f = msm_sat_filter(lo, hi);
    for (int k = 0; k < 4; ++k) {
      ASSERT_GE(f.x[k], -1);
      ASSERT_LE(f.x[k], w - 1);
      ASSERT_GE(f.y[k], -1);
      ASSERT_LE(f.y[k], h - 1);
    }
    ASSERT_LE(f.x[3] - f.x[0], W) << lo.x << " " << hi.x;
    ASSERT_LE(f.y[3] - f.y[0], W) << lo.y << " " << hi.y;
    vec4 got = nine_region(t, lo, hi, scale);
    dvec4 want = box_filter(t, lo, hi, scale);
    for (int c = 0; c < 4; ++c) {
      worst = std::max(worst, std::abs(double(got[c]) - want[c]));
      ASSERT_NEAR(got[c], want[c], 2e-6) << "region " << lo.x << "," << lo.y << " - " << hi.x << "," << hi.y;
    }
  };
  for (int i = 0; i < 3000; ++i) {
    vec2 size(0.01f + float(W - 1 - 0.01) * unit(rng) * (i % 3 == 0 ? 0.1f : 1.0f),
              0.01f + float(W - 1 - 0.01) * unit(rng) * (i % 5 == 0 ? 0.1f : 1.0f));
    vec2 lo(unit(rng) * (float(w) - size.x), unit(rng) * (float(h) - size.y));
    if (i % 7 == 0) lo = floor(lo);                   // integral left/top border
    if (i % 11 == 0) size = floor(size) + vec2(1.0f); // integral width
    if (i % 13 == 0) lo.x = 0.0f;                     // at the map's edges
    if (i % 17 == 0) lo.y = float(h) - size.y;
    check(lo, min(lo + size, vec2(float(w), float(h))));
  }
  check(vec2(3.25f, 4.5f), vec2(3.75f, 4.625f)); // inside one texel
  check(vec2(3.0f, 4.0f), vec2(4.0f, 5.0f));     // exactly one texel
  check(vec2(3.5f, 4.5f), vec2(4.5f, 5.5f));     // one texel's size over four: bilinear
  check(vec2(0.0f, 0.0f), vec2(26.0f, 26.0f));   // W - 1 wide at the corner
  check(vec2(w - 26.0f, h - 26.0f), vec2(float(w), float(h)));
  check(vec2(10.5f, 10.5f), vec2(36.5f, 36.5f)); // W - 1 wide, touching W texels
  std::printf("[sat] nine-region query vs exact box filter: max |error| %.2e\n", worst);
  // A one-texel box at a texel-center offset is bilinear interpolation of the texels.
  vec4 bilinear = nine_region(t, vec2(10.3f, 20.6f), vec2(11.3f, 21.6f), scale);
  auto q = [&](int x, int y) { return dvec4(t.q[size_t(y) * size_t(w) + size_t(x)]) / double(scale); };
  dvec4 expect = 0.7 * 0.4 * q(10, 20) + 0.3 * 0.4 * q(11, 20) + 0.7 * 0.6 * q(10, 21) + 0.3 * 0.6 * q(11, 21);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(bilinear[c], expect[c], 2e-6);
}

// Six moments: Θ6* split over two RGBA tables and joined back; a query over a constant region
// returns the texel's moments within the quantization step.
TEST(Sat, SixMomentsInTwoTables) {
  const int nt = 27 * 27;
  const uint scale = msm_sat_scale(nt);
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<float> depth(-1.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    Moments6 q = msm_theta6_star(msm_moments6(depth(rng)));
    SatTexels6 split = msm_sat_split6(q);
    Moments6 joined = msm_sat_join6(split.a, split.b);
    EXPECT_EQ(joined.odd, q.odd);
    EXPECT_EQ(joined.even, q.even);
    EXPECT_EQ(split.b[2], 0.0f);
    EXPECT_EQ(split.b[3], 0.0f);
    // A 27 × 27 block of this texel: sums via four table values of a constant map.
    SatValues6 v = msm_sat_quantize6(q, scale);
    auto S = [&](int x, int y) { // table value of the constant map at (x, y)
      uint n = uint((x + 1) * (y + 1));
      return SatValues6(v.a * n, v.b * n);
    };
    SatValues6 sum = msm_sat_rect_sum6(S(40, 30), S(13, 30), S(40, 3), S(13, 3)); // 27 × 27
    Moments6 avg = msm_sat_rect_average6(sum, nt, scale);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(avg.odd[c], std::clamp(q.odd[c], 0.0f, 1.0f), 0.5 / scale + 1e-7);
      EXPECT_NEAR(avg.even[c], std::clamp(q.even[c], 0.0f, 1.0f), 0.5 / scale + 1e-7);
    }
  }
}

// The grid-aligned rectangle of a continuous region (JCGT §4.5): the touched texels, clamped.
TEST(Sat, GridRectangles) {
  ivec2 size(64, 48);
  SatRect r = msm_sat_grid_rect(vec2(2.5f, 3.0f), vec2(7.0f, 9.25f), size);
  EXPECT_EQ(r.lo, ivec2(2, 3));
  EXPECT_EQ(r.hi, ivec2(6, 9));
  EXPECT_EQ(msm_sat_rect_texels(r), 5 * 7);
  r = msm_sat_grid_rect(vec2(-3.0f, 40.5f), vec2(0.5f, 60.0f), size);
  EXPECT_EQ(r.lo, ivec2(0, 40));
  EXPECT_EQ(r.hi, ivec2(0, 47));
  r = msm_sat_grid_rect(vec2(10.0f, 10.0f), vec2(10.0f, 10.0f), size); // empty: one texel
  EXPECT_EQ(msm_sat_rect_texels(r), 1);
}

} // namespace
