// The edges of the math: the reconstructions where an independent check broke them,
// swept by class against the double-precision oracles. Classes of depth distributions:
//  - near end: an occluder at the near end of the depth range (0 in [0,1], -1 in [-1,1]), alone
//    or beside a receiver surface (the receiver on it);
//  - far end: depths clamped to both ends (JCGT §2.5's worst case), with or without a third;
//  - receiver on an atom: 1-3 depths, the receiver exactly on one, or a few ulps / 1e-6 / 1e-4 off;
//  - cluster: 2-5 depths within 1e-6..1e-3 of each other, the receiver on one of them;
// through every storage path (the vector the reconstruction receives: stored, loaded, biased).
// Tolerance rule (oracle_range.h): the reference is the range of the sharp bound over the input
// vector moved by up to kUlps units in the last place per component; a result outside that range
// is the algorithm's fault, not the input's rounding. Inputs outside the moment space for every
// such move have no sharp bound; for them the tests check the side the technique errs on
// (docs/techniques.md, "Outside the moment space"): never darker than the distribution the texel
// came from, plus the bias.
// Measured values are printed as "[edges]" lines and recorded as math.edges.*.
#include "msm/blocker.h"
#include "msm/msm.h"
#include "msm/sat.h"
#include "msm/soft.h"
#include "msm/techniques.h"
#include "msm/test/figures.h"
#include "oracle_range.h"
#include "test_distributions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace msm;

constexpr int kUlps = 4;   // the box of the tolerance rule, per component
constexpr int kRandom = 8; // random vectors in the box besides its corners
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// ================================ Cases ================================

// A depth distribution in [-1,1] and a receiver, with the same depths in [0,1].
struct Case {
  const char* kind;
  test::Distribution d;  // [-1,1] depth, weights summing to 1
  test::Distribution du; // the same in [0,1]
  double zf;             // receiver in [-1,1] (double: its [0,1] image is rounded separately)
  float signed_zf() const { return float(zf); }
  float unit_zf() const { return float(0.5 * zf + 0.5); }
};

const char* const kKinds[] = {"near end", "far end", "receiver on an atom", "cluster"};

Case make_case(int kind, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Case c{kKinds[kind], {}, {}, 0.0};
  test::Distribution& d = c.d;
  if (kind == 0) { // near end, alone or beside a receiver surface
    d = {{-1.0}, {1.0}};
    c.zf = -1.0 + 2.0 * u(rng);
    if (u(rng) < 0.5) {
      d = {{-1.0, -1.0 + 2.0 * u(rng)}, {0.5, 0.5}};
      c.zf = d.z[1];
    }
    if (u(rng) < 0.2) c.zf = -1.0 + std::pow(10.0, -1.0 - 5.0 * u(rng)); // just behind the near end
  } else if (kind == 1) {                                                // both ends, maybe a third depth
    d = {{-1.0, 1.0}, {0.05 + u(rng), 0.05 + u(rng)}};
    if (u(rng) < 0.5) d.z.push_back(-1.0 + 2.0 * u(rng)), d.w.push_back(0.05 + u(rng));
    c.zf = u(rng) < 0.3 ? d.z.back() : -1.0 + 2.0 * u(rng);
    if (u(rng) < 0.2) c.zf = 1.0 - std::pow(10.0, -1.0 - 5.0 * u(rng)); // just in front of the far end
  } else if (kind == 2) {                                               // receiver on an atom
    d = test::random_diracs(rng, 1 + int(u(rng) * 3.0) % 3, -1.0, 1.0);
    double atom = d.z[size_t(u(rng) * double(d.z.size())) % d.z.size()];
    int k = int(u(rng) * 4.0);
    double offset = k == 0 ? 0.0 : k == 1 ? (u(rng) - 0.5) * 1e-6 : k == 2 ? (u(rng) - 0.5) * 2e-4 : 0.0;
    c.zf = atom + offset;
    if (k == 3) c.zf = double(test::ulp_step(float(atom), int(u(rng) * 9.0) - 4));
  } else { // cluster, the receiver on one of its depths
    double centre = -1.0 + 2.0 * u(rng), spacing = std::pow(10.0, -6.0 + 3.0 * u(rng));
    int n = 2 + int(u(rng) * 4.0) % 4;
    for (int i = 0; i < n; ++i) d.z.push_back(std::min(1.0, centre + i * spacing)), d.w.push_back(0.1 + u(rng));
    c.zf = d.z[size_t(u(rng) * double(n)) % size_t(n)];
  }
  double sum = 0.0;
  for (double w : d.w) sum += w;
  for (double& w : d.w) w /= sum;
  c.du = d;
  for (double& z : c.du.z) z = 0.5 * z + 0.5;
  return c;
}

// ================================ Storage paths ================================

// What a four-moment reconstruction receives: the stored, loaded and biased vector.
struct Path4 {
  const char* name;
  bool unit;                               // [0,1] depth (2015) or [-1,1] (JCGT)
  std::function<vec4(const Case&)> biased; // the vector the reconstruction sees
};

vec4 sat_texel(vec4 b) { // one texel of a 27² table: quantized to 22.5 bits, queried alone
  uint scale = msm_sat_scale(27 * 27);
  return msm_soft_moments4(msm_sat_rect_average(msm_sat_quantize(msm_theta4_star(b), scale), 1, scale), scale);
}

std::vector<Path4> paths4() {
  return {
      {"[0,1] float (2015)", true,
       [](const Case& c) { return msm_apply_bias(test::moments4f(c.du), msm_moment_bias(MSM_REP_UNIT_FLOAT)); }},
      {"[0,1] θ4 16-bit (2015)", true,
       [](const Case& c) {
         return msm_raise_d2(msm_apply_bias(msm_theta4_inverse(msm_quantize_unorm16(msm_theta4(test::moments4f(c.du)))),
                                            msm_moment_bias(MSM_REP_UNIT_THETA4)),
                             MSM_MIN_D2_UNIT_16BIT);
       }},
      {"[-1,1] float (JCGT)", false,
       [](const Case& c) { return msm_apply_bias(test::moments4f(c.d), msm_moment_bias(MSM_REP_SIGNED_FLOAT)); }},
      {"[-1,1] Θ4* 16-bit (JCGT)", false,
       [](const Case& c) {
         return msm_apply_bias(msm_theta4_star_inverse(msm_quantize_unorm16(msm_theta4_star(test::moments4f(c.d)))),
                               msm_moment_bias(MSM_REP_SIGNED_THETA4));
       }},
      {"SAT Θ4* 32-bit table (mssm4)", false, [](const Case& c) { return sat_texel(test::moments4f(c.d)); }},
  };
}

Moments6 moments6f(const test::Distribution& d) {
  std::vector<double> b = test::power_moments(d, 6);
  return Moments6(vec3(float(b[1]), float(b[3]), float(b[5])), vec3(float(b[2]), float(b[4]), float(b[6])));
}

struct Path6 {
  const char* name;
  std::function<Moments6(const Case&)> biased;
};

std::vector<Path6> paths6() {
  return {
      {"6MSM float", [](const Case& c) { return msm_apply_bias6(moments6f(c.d), msm_moment_bias6(MSM_REP6_FLOAT)); }},
      {"6MSM Θ6* 16-bit",
       [](const Case& c) {
         return msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm16(msm_theta6_star(moments6f(c.d)))),
                                msm_moment_bias6(MSM_REP6_UNORM16));
       }},
      {"6MSM Θ6* 10-bit",
       [](const Case& c) {
         return msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm10(msm_theta6_star(moments6f(c.d)))),
                                msm_moment_bias6(MSM_REP6_UNORM10));
       }},
      {"SAT Θ6* 32-bit tables (mssm6)",
       [](const Case& c) {
         uint scale = msm_sat_scale(27 * 27);
         return msm_soft_moments6(
             msm_sat_rect_average6(msm_sat_quantize6(msm_theta6_star(moments6f(c.d)), scale), 1, scale), scale);
       }},
  };
}

std::vector<float> as_vector(vec4 b) { return {b[0], b[1], b[2], b[3]}; }
std::vector<float> as_vector(Moments6 b) { return {b.odd[0], b.even[0], b.odd[1], b.even[1], b.odd[2], b.even[2]}; }

// Z(z < zf) of the biased distribution (1 - α) Z + α Z*: the sharp bound of the exactly biased
// vector is at most this, whatever the float vector became.
double biased_cdf(const test::Distribution& d, double zf, double alpha, const test::Distribution& bstar) {
  return (1.0 - alpha) * test::cdf_less(d, zf) + alpha * test::cdf_less(bstar, zf);
}
// The biasing distributions as Diracs: ½δ0 + ½δ1 on [0,1]; on [-1,1] the b* = (1, 0, s, 0, s) of
// JCGT is s/2 δ(-1) + (1 - s) δ(0) + s/2 δ(1).
test::Distribution bstar_unit() { return {{0.0, 1.0}, {0.5, 0.5}}; }
test::Distribution bstar_signed(double s) { return {{-1.0, 0.0, 1.0}, {0.5 * s, 1.0 - s, 0.5 * s}}; }

// ================================ Statistics ================================

struct Tally {
  std::string name;
  long cases = 0, outside = 0;  // outside: no vector within the box is inside the moment space
  std::vector<double> distance; // how far the result lies outside the range
  double darker_outside = 0.0;  // outside cases: how far above the biased CDF
  void add_distance(double e) { distance.push_back(e); }
  double quantile(double q) {
    std::sort(distance.begin(), distance.end());
    return distance.empty() ? 0.0 : distance[size_t(q * double(distance.size() - 1))];
  }
  void print() {
    std::printf("[edges] %-34s cases %5ld, outside the moment space %4ld | distance to the oracle's range: p99 %.2e "
                "max %.2e | outside: darker than the biased CDF by at most %.2e\n",
                name.c_str(), cases, outside, quantile(0.99), quantile(1.0), darker_outside);
  }
};

// A storage path's lower and upper bounds against the range of Algorithm 1 over the box.
struct BoundTallies {
  Tally lower, upper;
  explicit BoundTallies(const std::string& path)
      : lower{path, 0, 0, {}, 0.0}, upper{path + " (upper)", 0, 0, {}, 0.0} {}
  // Counts a case; false where no vector of the box is inside the moment space (no range).
  bool add(const test::BoundRange& range, vec2 bounds) {
    ++lower.cases, ++upper.cases;
    if (range.feasible == 0) {
      ++lower.outside, ++upper.outside;
      return false;
    }
    lower.add_distance(range.lower_distance(bounds.x));
    upper.add_distance(range.upper_distance(bounds.y));
    return true;
  }
  void print() {
    lower.print();
    upper.print();
  }
};

// ================================ Tests ================================

// The worst distance of a storage path's bound to the oracle's range, with the limit asserted; the key
// names the path by the ASCII letters and digits of its name (its depth range and Greek letters spelt out).
void record_edge(const std::string& path, const std::string& bound, double distance, double limit) {
  std::string name = path;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"[0,1]", "unit"},
                                 {"[-1,1]", "signed"},
                                 {"θ", "theta"},
                                 {"Θ", "Theta"},
                                 {"*", "star"}})
    for (size_t at = name.find(from); at != std::string::npos; at = name.find(from, at + to.size()))
      name.replace(at, from.size(), to);
  std::string slug;
  for (const char c : name)
    if (static_cast<unsigned char>(c) < 0x80 && std::isalnum(static_cast<unsigned char>(c)))
      slug += c;
    else if (!slug.empty() && slug.back() != '_')
      slug += '_';
  while (!slug.empty() && slug.back() == '_') slug.pop_back();
  test::record_figure("math.edges." + bound + "." + slug + ".distance_max", distance,
                      {.below = limit,
                       .meaning = path + ": the bound's worst distance to the oracle's range over the input moved by "
                                         "4 ulps"});
}

// Hamburger 4MSM (lower and upper bound) on every four-moment storage path, every class: inside
// the range of JCGT Algorithm 1 over the box. Measured (4000 cases per path) lower max 2.2e-7,
// upper max 1.3e-4: the upper bound adds w0 = 1 / (c0 + zf (c1 + zf c2)), whose float rounding
// of c the box does not cover where w0 is steep. Tolerances 1e-5 and 5e-4. Outside the moment
// space for every vector of the box (none now; without msm_raise_d2 the 2015 θ4 16-bit path had
// 591 of 4000 there, its 16-bit rounding being far more than the box of the decoded float vector,
// reading up to 0.64 darker than the biased CDF) the lower bound must not read darker than the
// biased distribution the texel came from by more than 0.05.
TEST(Edges, Hamburger4AgainstAlgorithm1OnEveryStoragePath) {
  for (const Path4& path : paths4()) {
    std::mt19937_64 rng(1900);
    BoundTallies tallies(path.name);
    for (int i = 0; i < 4000; ++i) {
      Case c = make_case(i % 4, rng);
      vec4 b = path.biased(c);
      float zf = path.unit ? c.unit_zf() : c.signed_zf();
      vec2 bounds = msm_hamburger4_bounds(b, zf);
      ASSERT_TRUE(bounds.x >= 0.0f && bounds.x <= bounds.y && bounds.y <= 1.0f) << path.name << " case " << i;
      test::BoundRange range = test::hamburger_range(as_vector(b), zf, kUlps, kRandom, rng);
      if (!tallies.add(range, bounds)) {
        MomentBias4 bias = msm_moment_bias(path.unit ? MSM_REP_UNIT_FLOAT : MSM_REP_SIGNED_FLOAT);
        double cdf = path.unit ? biased_cdf(c.du, zf, bias.alpha, bstar_unit())
                               : biased_cdf(c.d, zf, bias.alpha, bstar_signed(bias.bstar[1]));
        tallies.lower.darker_outside = std::max(tallies.lower.darker_outside, double(bounds.x) - cdf);
        continue;
      }
      if (range.lower_distance(bounds.x) > 1e-5 && std::getenv("MSM_EDGES_VERBOSE"))
        std::printf("  %s %s zf %.9g b (%.9g %.9g %.9g %.9g): lower %.6g range [%.6g, %.6g] (%d feasible)\n", path.name,
                    c.kind, zf, b[0], b[1], b[2], b[3], bounds.x, range.lower_min, range.lower_max, range.feasible);
    }
    tallies.print();
    EXPECT_LE(tallies.lower.quantile(1.0), 1e-5) << path.name;
    record_edge(path.name, "lower", tallies.lower.quantile(1.0), 1e-5);
    EXPECT_LE(tallies.upper.quantile(1.0), 5e-4) << path.name;
    record_edge(path.name, "upper", tallies.upper.quantile(1.0), 5e-4);
    EXPECT_LE(tallies.lower.darker_outside, 0.05) << path.name;
  }
}

// Hausdorff 4MSM on the four linear storage paths, every class, against the LP on [lo, hi]
// (exact rational re-solve, refined grid). The LP is slow (~0.3 s), so the range is lazy: the
// input vector first; only where the result differs from its bound by more than the grid's slack
// (1e-3: a grid can only raise the LP's lower bound) are 6 corners of the box solved too.
// (For boxes that straddle the boundary of the moment space, up to two segments are bisected to
// it, 10 LP solves each.) Before the fix: NaN at the near end read lit (0 against ~1), the
// four-atom branch read 0.98 against a sharp 0.27 on clusters (its lower bound failed by up to
// 0.999). Measured distance 0 with slack 1e-3 (the largest difference from the input's own bound
// is 8.9e-4); outside the moment space of [lo, hi] for the whole box (39 of 96: depths at the
// ends, rounded outwards) no result is darker than the biased CDF by more than 2.2e-5 (0.51
// before the fallback to Hamburger for such vectors). Tolerance 1e-3.
TEST(Edges, Hausdorff4AgainstTheLinearProgram) {
  const double slack = 1e-3;
  long cases = 0, outside = 0, perturbed = 0;
  double worst = 0.0, darker_outside = 0.0, largest_difference = 0.0;
  for (const Path4& path : paths4()) {
    if (std::string(path.name).rfind("SAT", 0) == 0) continue; // no Hausdorff technique reads the tables
    std::mt19937_64 rng(1901);
    for (int i = 0; i < 24; ++i) {
      Case c = make_case(i % 4, rng);
      vec4 b = path.biased(c);
      float lo = path.unit ? 0.0f : -1.0f, zf = path.unit ? c.unit_zf() : c.signed_zf();
      float result = msm_hausdorff4_lower(b, zf, lo, 1.0f);
      ASSERT_TRUE(result >= 0.0f && result <= 1.0f) << path.name << " case " << i;
      ++cases;
      std::vector<double> input_vector{b[0], b[1], b[2], b[3]};
      test::LpLower input = test::hausdorff_lp(input_vector, zf, lo, 1.0);
      if (input.feasible) largest_difference = std::max(largest_difference, std::abs(result - input.lower));
      if (input.feasible && std::abs(result - input.lower) <= slack) continue;
      ++perturbed;
      test::BoundRange range;
      std::vector<std::vector<double>> inside, outside_corners;
      (input.feasible ? inside : outside_corners).push_back(input_vector);
      if (input.feasible) range.add(input.lower, 1.0);
      for (int k = 0; k < 6; ++k) {
        std::vector<double> p;
        uint64_t pattern = rng();
        for (int j = 0; j < 4; ++j) p.push_back(double(test::ulp_step(b[j], (pattern >> j) & 1 ? kUlps : -kUlps)));
        test::LpLower lp = test::hausdorff_lp(p, zf, lo, 1.0);
        if (lp.feasible) range.add(lp.lower, 1.0);
        (lp.feasible ? inside : outside_corners).push_back(p);
      }
      bool beyond = result < range.lower_min - slack || result > range.lower_max + slack;
      for (size_t k = 0; beyond && k < 2 && !inside.empty() && k < outside_corners.size(); ++k) {
        test::LpLower edge = test::hausdorff_lp_boundary(inside[0], outside_corners[k], zf, lo, 1.0);
        if (edge.feasible) range.add(edge.lower, 1.0);
        beyond = result < range.lower_min - slack || result > range.lower_max + slack;
      }
      if (range.feasible == 0) {
        ++outside;
        MomentBias4 bias = msm_moment_bias(path.unit ? MSM_REP_UNIT_FLOAT : MSM_REP_SIGNED_FLOAT);
        double cdf = path.unit ? biased_cdf(c.du, zf, bias.alpha, bstar_unit())
                               : biased_cdf(c.d, zf, bias.alpha, bstar_signed(bias.bstar[1]));
        darker_outside = std::max(darker_outside, double(result) - cdf);
        if (double(result) - cdf > 1e-3 && std::getenv("MSM_EDGES_VERBOSE"))
          std::printf("  outside: %s %s zf %.9g b (%.9g %.9g %.9g %.9g): %.6g, biased CDF %.6g, hamburger %.6g\n",
                      path.name, c.kind, zf, b[0], b[1], b[2], b[3], result, cdf, msm_hamburger4_lower(b, zf));
        continue;
      }
      double distance = std::max(range.lower_min - slack - result, result - range.lower_max - slack);
      worst = std::max(worst, distance);
      EXPECT_LE(distance, 0.0) << path.name << " " << c.kind << " zf " << zf << " b (" << b[0] << ", " << b[1] << ", "
                               << b[2] << ", " << b[3] << "): " << result << " against [" << range.lower_min << ", "
                               << range.lower_max << "]";
    }
  }
  std::printf("[edges] hausdorff4 vs LP: %ld cases, %ld beyond the input's bound ± %.0e, %ld outside the moment "
              "space of the interval | largest difference from the input's bound %.2e, distance to the range %.2e "
              "| outside: darker than the biased CDF by at most %.2e\n",
              cases, perturbed, slack, outside, largest_difference, std::max(worst, 0.0), darker_outside);
  EXPECT_LE(darker_outside, 1e-3);
}

// Hamburger 6MSM, lower and upper bound and their blend, on the six-moment storage paths, against
// JCGT Algorithm 1 (m = 6) over the box. No biased six-moment vector of these classes lies
// outside the moment space. Measured max distance (2000 cases per path): lower 2.0e-7, upper
// 1.2e-4. Tolerances 5e-3 (the roots of the cubic carry ~eps^(1/3) near a triple root;
// hamburger6_test's figures).
TEST(Edges, Hamburger6AgainstAlgorithm1OnEveryStoragePath) {
  for (const Path6& path : paths6()) {
    std::mt19937_64 rng(1902);
    BoundTallies tallies(path.name);
    for (int i = 0; i < 2000; ++i) {
      Case c = make_case(i % 4, rng);
      Moments6 b = path.biased(c);
      float zf = c.signed_zf();
      vec2 bounds = msm_hamburger6_bounds(b, zf);
      float beta = float(i % 5) / 4.0f, blend = msm_hamburger6_blend(b, zf, beta);
      ASSERT_TRUE(bounds.x >= 0.0f && bounds.x <= bounds.y && bounds.y <= 1.0f) << path.name << " case " << i;
      ASSERT_TRUE(blend >= bounds.x && blend <= bounds.y) << path.name << " case " << i;
      tallies.add(test::hamburger_range(as_vector(b), zf, kUlps, kRandom, rng), bounds);
    }
    tallies.print();
    EXPECT_EQ(tallies.lower.outside, 0) << path.name;
    EXPECT_LE(tallies.lower.quantile(1.0), 5e-3) << path.name;
    record_edge(path.name, "lower", tallies.lower.quantile(1.0), 5e-3);
    EXPECT_LE(tallies.upper.quantile(1.0), 5e-3) << path.name;
    record_edge(path.name, "upper", tallies.upper.quantile(1.0), 5e-3);
  }
}

// The non-linear maps (HPG Algorithm 3 on Φ, unquantized and through 64 and 32 bits) against JCGT
// Algorithm 1 on the moments they stand for (HPG Eq. (4) in double), over the box of their four
// fields. Measured max distance 2.0e-6 (unquantized), 6.2e-6 (64 bits), 2.8e-5 (32 bits);
// tolerance 1e-4.
TEST(Edges, NonLinearAgainstAlgorithm1) {
  const char* names[] = {"NL unquantized", "NL 64-bit", "NL 32-bit"};
  for (int k = 0; k < 3; ++k) {
    std::mt19937_64 rng(1903);
    Tally tally{names[k], 0, 0, {}, 0.0};
    for (int i = 0; i < 3000; ++i) {
      Case c = make_case(i % 4, rng);
      NonLinearMoments m = msm_nl_from_filtered(test::moments4f(c.d));
      if (k == 1) m = msm_nl_quantize64(m);
      if (k == 2) m = msm_nl_quantize32(m);
      float zf = c.signed_zf(), result = msm_nl_shadow(m, zf);
      ASSERT_TRUE(result >= 0.0f && result <= 1.0f) << names[k] << " case " << i;
      // The input Algorithm 3 works on: y1 = y2, v2 = 0 or 1 moved away by MSM_NL_TOLERANCE and ξ4
      // floored (nonlinear.h, HPG §3.4); with them, a valid moment vector.
      float y2 = std::max(m.y2, m.y1 + MSM_NL_TOLERANCE);
      float v2 = std::clamp(m.v2, MSM_NL_TOLERANCE, 1.0f - MSM_NL_TOLERANCE);
      float xi4 = std::max(m.xi4, MSM_NL_XI4_SHADING_MIN);
      test::BoundRange range;
      for (const std::vector<float>& p : test::perturbations({m.y1, y2, v2, xi4}, kUlps, kRandom, rng)) {
        oracle::MomentBounds o = oracle::moment_bounds(test::nl_moments(p[0], p[1], p[2], p[3]), zf);
        if (o.ok) range.add(o.lower, std::min(o.upper, 1.0));
      }
      ++tally.cases;
      if (range.feasible == 0) {
        ++tally.outside;
        continue;
      }
      tally.add_distance(range.lower_distance(result));
    }
    tally.print();
    EXPECT_LE(tally.quantile(1.0), 1e-4) << names[k];
    record_edge(names[k], "lower", tally.quantile(1.0), 1e-4);
  }
}

// A NaN texel reads lit (0) in every representation, for every receiver in the depth range
// (up to the last 32-bit depth bin, 1 - 1/1023 in [-1,1]), unquantized or after storage, and the
// soft path's blocker search finds no blocker. Before: 0 unquantized, 1 after the 64/32-bit round
// trip (codes 0 decode to depth -1) and 1 for 16-bit linear storage.
TEST(Edges, NanTexelReadsLitInEveryRepresentation) {
  const vec4 nan4 = vec4(kNaN);
  for (int t = MSM_TECH_HAMBURGER_128_UNIT; t <= MSM_TECH_HAUSDORFF_64; ++t) {
    bool unorm16 = t == MSM_TECH_HAMBURGER_64_THETA4 || t == MSM_TECH_HAMBURGER_64 ||
                   t == MSM_TECH_HAUSDORFF_64_THETA4 || t == MSM_TECH_HAUSDORFF_64;
    MsmTexel texel = MsmTexel(unorm16 ? msm_quantize_unorm16(nan4) : nan4, vec4(0.0f));
    for (int j = 0; j <= 100; ++j)
      EXPECT_EQ(msm_technique_shadow(t, texel, float(j) / 100.0f, msm_technique_default_params(t)), 0.0f)
          << "technique " << t << " zf " << j;
  }
  Moments6 nan6 = Moments6(vec3(kNaN), vec3(kNaN));
  for (int t : {MSM_TECH_MSM6_192, MSM_TECH_MSM6_96}) {
    Moments6 m = t == MSM_TECH_MSM6_96 ? msm_quantize_unorm16(nan6) : nan6;
    MsmTexel texel = MsmTexel(vec4(m.odd, m.even[0]), vec4(m.even[1], m.even[2], 0.0f, 0.0f));
    for (int j = 0; j <= 100; ++j)
      EXPECT_EQ(msm_technique_shadow(t, texel, float(j) / 100.0f, msm_technique_default_params(t)), 0.0f);
  }
  Moments6 ten = msm_theta6_star_inverse(msm_quantize_unorm10(nan6));
  NonLinearMoments nl = msm_nl_from_filtered(nan4);
  for (int j = 0; j <= 1000; ++j) {
    float zf = -1.0f + 2.0f * float(j) / 1000.0f;
    EXPECT_EQ(msm_hamburger6_lower(msm_apply_bias6(ten, msm_moment_bias6(MSM_REP6_UNORM10)), zf), 0.0f);
    EXPECT_EQ(msm_nl_shadow(nl, zf), 0.0f) << zf;
    EXPECT_EQ(msm_nl_shadow(msm_nl_quantize64(nl), zf), 0.0f) << zf;
    if (zf <= 1.0f - 1.0f / 1023.0f) {
      EXPECT_EQ(msm_nl_shadow(msm_nl_quantize32(nl), zf), 0.0f) << zf;
      EXPECT_EQ(msm_nl_shadow(msm_nl_unpack32(msm_nl32_encode(nan4)), zf), 0.0f) << zf; // the renderer's encoders
    }
    EXPECT_EQ(msm_nl_shadow(msm_nl64_decode(msm_nl64_encode(nan4)), zf), 0.0f) << zf;
  }
  // Summed-area tables: a NaN texel quantizes to 0 (sat.h); queried alone it is invalid.
  uint scale = msm_sat_scale(27 * 27);
  vec4 q = msm_sat_rect_average(msm_sat_quantize(nan4, scale), 1, scale);
  for (int j = 0; j <= 100; ++j) {
    float zf = -1.0f + 2.0f * float(j) / 100.0f;
    EXPECT_EQ(msm_soft_shadow4(q, zf, MSM_SOFT_UMBRA_EPSILON, scale), 0.0f);
    BlockerResult r = msm_soft_blocker4(q, zf, scale);
    EXPECT_EQ(r.shadow, 0.0f);
    EXPECT_TRUE(r.depth >= -1.0f && r.depth <= 1.0f);
  }
}

// Any input, however broken, gives ordered bounds in [0,1] and a blocker depth in the depth range:
// garbage moment vectors (uniform in [-2, 2], huge, with NaN and ±inf components) at receivers
// anywhere, ±inf, NaN, ±1e30 included. Before: zf = +inf gave lower 1 > upper 0 (4MSM), garbage
// six-moment vectors lower > upper in 19% of cases.
TEST(Edges, BoundsStayOrderedForAnyInput) {
  std::mt19937_64 rng(1904);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  const float specials[] = {kNaN, kInf, -kInf, 1e30f, -1e30f, 1e8f, -1e8f, 3e38f, 0.0f, 1.0f, -1.0f};
  auto component = [&](int kind) {
    if (kind == 0) return u(rng);
    if (kind == 1) return specials[rng() % std::size(specials)];
    return u(rng) * std::pow(10.0f, float(rng() % 40));
  };
  for (int i = 0; i < 200000; ++i) {
    int kind = i % 10 < 6 ? 0 : i % 10 < 8 ? 1 : 2;
    vec4 b4 = vec4(component(kind), component(kind), component(kind), component(kind));
    Moments6 b6 = Moments6(vec3(component(kind), component(kind), component(kind)),
                           vec3(component(kind), component(kind), component(kind)));
    float zf = i % 3 == 0 ? specials[rng() % std::size(specials)] : u(rng);
    vec2 h4 = msm_hamburger4_bounds(b4, zf);
    ASSERT_TRUE(h4.x >= 0.0f && h4.x <= h4.y && h4.y <= 1.0f) << "4MSM case " << i << " zf " << zf;
    vec2 h6 = msm_hamburger6_bounds(b6, zf);
    ASSERT_TRUE(h6.x >= 0.0f && h6.x <= h6.y && h6.y <= 1.0f) << "6MSM case " << i << " zf " << zf;
    float blend = msm_hamburger6_blend(b6, zf, 0.5f);
    ASSERT_TRUE(blend >= h6.x && blend <= h6.y) << "6MSM blend case " << i;
    float lo = i % 2 ? 0.0f : -1.0f, hausdorff = msm_hausdorff4_lower(b4, zf, lo, 1.0f);
    ASSERT_TRUE(hausdorff >= 0.0f && hausdorff <= 1.0f) << "Hausdorff case " << i;
    float nl = msm_nl_shadow(NonLinearMoments(b4[0], b4[1], b4[2], b4[3]), zf);
    ASSERT_TRUE(nl >= 0.0f && nl <= 1.0f) << "NL case " << i;
    float zb = u(rng) * 0.6f; // a receiver in the depth range
    for (BlockerResult r : {msm_blocker4(b4, zb), msm_blocker4_upper(b4, zb, 1e-3f, 0.1f), msm_blocker6(b6, zb),
                            msm_blocker6_upper(b6, zb, 1e-3f, 0.1f)}) {
      ASSERT_TRUE(r.depth >= std::min(-1.0f, zb) && r.depth <= zb + 1e-6f && r.shadow >= 0.0f && r.shadow <= 1.0f)
          << "blocker case " << i << " zb " << zb << ": " << r.depth << " " << r.shadow << " b4 " << b4[0] << " "
          << b4[1] << " " << b4[2] << " " << b4[3];
    }
  }
  // Valid moments and receivers beyond everything: both bounds 1 (or 0 in front).
  vec4 b = msm_apply_bias(msm_moments4(0.3f), msm_moment_bias(MSM_REP_SIGNED_FLOAT));
  Moments6 b6 = msm_apply_bias6(msm_moments6(0.3f), msm_moment_bias6(MSM_REP6_FLOAT));
  for (float zf : {kInf, 1e30f, 1e8f}) {
    EXPECT_EQ(msm_hamburger4_bounds(b, zf), vec2(1.0f));
    EXPECT_EQ(msm_hamburger6_bounds(b6, zf), vec2(1.0f));
    EXPECT_EQ(msm_hamburger4_bounds(b, -zf), vec2(0.0f));
    EXPECT_EQ(msm_hamburger6_bounds(b6, -zf), vec2(0.0f));
  }
}

// The soft techniques' blocker depth (JCGT Eq. (4), Kneiphof Eq. (19)) stays in the depth range
// [-1, 1] and at or in front of the receiver, for every class through the summed-area tables, four
// and six moments, both estimators. Before: down to -2.33 (a root of the canonical distribution
// below -1 with the bias's weight).
TEST(Edges, BlockerDepthStaysInTheDepthRange) {
  std::mt19937_64 rng(1905);
  uint scale = msm_sat_scale(27 * 27);
  const vec4 eq4 = msm_technique_default_params(MSM_TECH_MSSM4), eq19 = msm_technique_default_params(MSM_TECH_MSSM6);
  for (int i = 0; i < 40000; ++i) {
    Case c = i % 5 == 4 ? Case{"random", test::random_distribution(rng, -1.0, 1.0), {}, 0.0} : make_case(i % 4, rng);
    if (i % 5 == 4) c.zf = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
    vec4 q4 = msm_sat_rect_average(msm_sat_quantize(msm_theta4_star(test::moments4f(c.d)), scale), 1, scale);
    Moments6 q6 = msm_sat_rect_average6(msm_sat_quantize6(msm_theta6_star(moments6f(c.d)), scale), 1, scale);
    float zf = c.signed_zf();
    for (BlockerResult r :
         {msm_soft_blocker4_select(q4, zf, eq4, scale), msm_soft_blocker4_select(q4, zf, eq19, scale),
          msm_soft_blocker6_select(q6, zf, eq4, scale), msm_soft_blocker6_select(q6, zf, eq19, scale)})
      ASSERT_TRUE(r.depth >= -1.0f && r.depth <= zf + 1e-6f && r.shadow >= 0.0f && r.shadow <= 1.0f)
          << c.kind << " case " << i << " zf " << zf << ": depth " << r.depth;
  }
}

// The question of JCGT §2.5 for every storage path: is b* the one measured after the transform
// the rounding happens in? Count biased vectors (single depths, two depths, random kernels) that
// are not positive definite in exact arithmetic, with the configured b* and with the other.
// Summed-area tables round Θ4* moments (22.5 bits for 27² kernels): 0.628 (JCGT App. D.4, the
// authors' code) leaves fewer outside than the float 0.375 did. Six-moment paths: none outside.
TEST(Edges, SatBiasTargetIsMeasuredAfterTheTransform) {
  auto positive_definite4 = [](vec4 b) {
    long double b1 = b[0], b2 = b[1], b3 = b[2], b4 = b[3], d1 = b2 - b1 * b1, l = b3 - b1 * b2;
    return d1 > 0 && b4 - b2 * b2 - l * l / d1 > 0;
  };
  auto positive_definite6 = [](Moments6 m) {
    long double h[7] = {1, m.odd[0], m.even[0], m.odd[1], m.even[1], m.odd[2], m.even[2]}, a[4][4];
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) a[i][j] = h[i + j];
    for (int k = 0; k < 4; ++k) {
      if (!(a[k][k] > 0)) return false;
      for (int i = k + 1; i < 4; ++i)
        for (int j = 3; j >= k; --j) a[i][j] -= a[i][k] / a[k][k] * a[k][j];
    }
    return true;
  };
  uint scale = msm_sat_scale(27 * 27);
  long sat375 = 0, sat628 = 0, theta375 = 0, theta628 = 0, six = 0, n = 0;
  std::mt19937_64 rng(1906);
  for (int i = 0; i < 60000; ++i, ++n) {
    test::Distribution d = i % 3 == 0   ? test::random_diracs(rng, 1, -1.0, 1.0)
                           : i % 3 == 1 ? test::random_diracs(rng, 2, -1.0, 1.0)
                                        : test::random_distribution(rng, -1.0, 1.0);
    vec4 b = test::moments4f(d);
    vec4 sat = msm_theta4_star_inverse(msm_sat_rect_average(msm_sat_quantize(msm_theta4_star(b), scale), 1, scale));
    vec4 s16 = msm_theta4_star_inverse(msm_quantize_unorm16(msm_theta4_star(b)));
    sat375 += !positive_definite4(msm_apply_bias(sat, MSM_ALPHA_SAT_INT32, MSM_BSTAR_SIGNED_FLOAT));
    sat628 += !positive_definite4(msm_apply_bias(sat, msm_moment_bias(MSM_REP_SAT_INT32)));
    theta375 += !positive_definite4(msm_apply_bias(s16, MSM_ALPHA_SIGNED_16BIT, MSM_BSTAR_SIGNED_FLOAT));
    theta628 += !positive_definite4(msm_apply_bias(s16, msm_moment_bias(MSM_REP_SIGNED_THETA4)));
    Moments6 b6 = moments6f(d);
    six += !positive_definite6(msm_apply_bias6(b6, msm_moment_bias6(MSM_REP6_FLOAT)));
    six += !positive_definite6(msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm16(msm_theta6_star(b6))),
                                               msm_moment_bias6(MSM_REP6_UNORM16)));
    six += !positive_definite6(msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm10(msm_theta6_star(b6))),
                                               msm_moment_bias6(MSM_REP6_UNORM10)));
  }
  std::printf("[edges] not positive definite after biasing, of %ld kernels: SAT (one texel) b* 0.375: %ld, 0.628: %ld "
              "(configured); Θ4* 16-bit 0.375: %ld, 0.628: %ld (configured); six moments, all paths: %ld\n",
              n, sat375, sat628, theta375, theta628, six);
  EXPECT_EQ(msm_moment_bias(MSM_REP_SAT_INT32).bstar, MSM_BSTAR_SIGNED_16BIT);
  EXPECT_LT(sat628, sat375);
  EXPECT_LE(theta628, theta375);
  EXPECT_EQ(six, 0);
}

// The pivot floor of Hamburger 4MSM (hamburger4.h): where D2 rounds to <= 0 the bound is that of
// the vector with D2 raised to one rounding of b4, not the two-atom limit (the old floor 1e-12).
//  - The case: a surface at 0.950902 ([0,1] float, 2015 bias), a receiver 3.5e-6 behind
//    it. The sharp bound of the exactly biased vector is 0.0044; the two-atom limit read 0.909.
//    The floor must read no more than that sharp bound (+1e-3): the light side.
//  - Self-shadowing: with the filtered techniques' depth bias (1e-5 in [0,1] depth) a flat
//    receiver on a single surface reads at most the bias's α/2 = 1e-6 plus rounding (1e-5).
//  - Leaking: 1e-3 behind a single surface (beyond any depth bias) the result may be lighter than
//    the exactly biased vector's sharp bound only as much as the float vector's own sharp bound
//    already is (0.093 in [0,1], 0.025 in [-1,1], before and after the floor): at most 0.1.
TEST(Edges, PivotFloorIsTheLightSide) {
  auto exactly_biased = [](const test::Distribution& d, MomentBias4 bias) {
    std::vector<double> b = test::power_moments(d, 4);
    for (int j = 1; j <= 4; ++j)
      b[size_t(j)] = (1.0 - bias.alpha) * b[size_t(j)] + bias.alpha * double(bias.bstar[j - 1]);
    return b;
  };
  const MomentBias4 unit = msm_moment_bias(MSM_REP_UNIT_FLOAT);
  test::Distribution surface{{0.950902}, {1.0}};
  float zf = float(0.950902 + 3.5e-6);
  oracle::MomentBounds sharp = oracle::moment_bounds(exactly_biased(surface, unit), zf);
  ASSERT_TRUE(sharp.ok);
  float result = msm_hamburger4_lower(msm_apply_bias(test::moments4f(surface), unit), zf);
  std::printf("[edges] surface at 0.950902, receiver 3.5e-6 behind: %.4f, sharp bound of the exactly biased vector "
              "%.4f (two-atom limit before: 0.909)\n",
              result, sharp.lower);
  EXPECT_LE(result, sharp.lower + 1e-3);
  for (int rep : {MSM_REP_UNIT_FLOAT, MSM_REP_SIGNED_FLOAT}) {
    MomentBias4 bias = msm_moment_bias(rep);
    double lo = rep == MSM_REP_UNIT_FLOAT ? 0.0 : -1.0;
    float self = 0.0f;
    double leak = 0.0;
    for (int i = 1; i < 1000; ++i) {
      double z = lo + (1.0 - lo) * double(i) / 1000.0;
      test::Distribution d{{z}, {1.0}};
      vec4 b = msm_apply_bias(test::moments4f(d), bias);
      self = std::max(self, msm_hamburger4_lower(b, float(z - 1e-5 * (1.0 - lo))));
      oracle::MomentBounds behind = oracle::moment_bounds(exactly_biased(d, bias), float(z + 1e-3));
      if (behind.ok) leak = std::max(leak, behind.lower - msm_hamburger4_lower(b, float(z + 1e-3)));
    }
    std::printf("[edges] single surfaces, %s float: flat receiver with depth bias reads at most %.2e; 1e-3 behind, "
                "lighter than the exactly biased sharp bound by at most %.3f\n",
                lo == 0.0 ? "[0,1]" : "[-1,1]", self, leak);
    EXPECT_LE(self, 1e-5f);
    EXPECT_LE(leak, 0.1);
  }
}

// How much darker than PCF (the CDF of the kernel) the reconstruction reads where the float vector
// carries least information: 1-3 random depths, one in three a pair 1e-6..1e-3 apart, receivers
// 1e-7 in front of a depth or 1e-5..3e-5 behind it. Before the pivot floor (two-atom limit where D2
// rounded to <= 0): up to 0.95 darker in [0,1] float (0.6 in the issue), 0.88 in [-1,1]. Measured
// now 0.227 and 0.036: what is left lies within the range of sharp bounds over the rounding of the
// float vector (Hamburger4AgainstAlgorithm1OnEveryStoragePath); a floor of 3-4 roundings would
// bring it to 0.06 / 0.01 at twice the leaking 1e-3 behind a surface (0.16 against 0.09), which
// is not taken. Tolerances 0.25 and 0.05. Also printed: how many biased vectors leave the moment
// space (2015: 9% of single depths).
TEST(Edges, FloatMomentsReadNoDarkerThanPcfThanRoundingAllows) {
  for (int rep : {MSM_REP_UNIT_FLOAT, MSM_REP_SIGNED_FLOAT}) {
    MomentBias4 bias = msm_moment_bias(rep);
    double lo = rep == MSM_REP_UNIT_FLOAT ? 0.0 : -1.0;
    std::mt19937_64 rng(1907);
    long outside = 0, n = 0;
    double darker = 0.0;
    for (int i = 0; i < 30000; ++i, ++n) {
      test::Distribution d = test::random_diracs(rng, 1 + i % 3, lo, 1.0);
      if (i % 3 == 1) d.z[1] = std::min(1.0, d.z[0] + std::pow(10.0, -6.0 + 3.0 * double(rng() % 1000) / 1000.0));
      vec4 b = msm_apply_bias(test::moments4f(d), bias);
      outside += !oracle::moment_bounds(std::vector<double>{1.0, b[0], b[1], b[2], b[3]}, 0.5).ok;
      for (int j = 0; j < 6; ++j) {
        float zf = float(d.z[size_t(j) % d.z.size()] + (j < 3 ? -1e-7 : 1e-5 * double(j - 2)));
        darker = std::max(darker, double(msm_hamburger4_lower(b, zf)) - test::cdf_less(d, zf));
      }
    }
    std::printf("[edges] %s float, 1-3 depths: %.2f%% of biased vectors outside the moment space; darker than PCF by "
                "at most %.3f\n",
                lo == 0.0 ? "[0,1]" : "[-1,1]", 100.0 * double(outside) / double(n), darker);
    EXPECT_LE(darker, lo == 0.0 ? 0.25 : 0.05);
  }
}

} // namespace
