// The tolerance rule of the tests that hold the float reconstructions against the double oracles
// where the problem is hardest (ends of the depth range, receivers on atoms, clusters of depths):
// a float moment vector is known only to its rounding, and near the boundary of the moment space
// the sharp bound changes by O(1) within that rounding. So the reference is not the oracle on the
// float vector alone but the RANGE of the oracle's bounds over the vectors within a few units in
// the last place (ulps) of it, per component: the corners of that box (every component moved by
// ±ulps), the vector itself and random integer steps in between. A result outside the range (plus
// a small slack for the oracle's own grid) is the algorithm's error, not the input's rounding.
// Perturbed vectors outside the moment space have no bounds and are left out; when none is inside,
// the range is empty (`feasible` = 0) and the caller decides what to check instead.
// Test helper, C++ only (the oracles are double/long double, independent of include/msm).
#pragma once
#include "msm/oracle/lp_oracle.h"
#include "msm/oracle/moment_oracle.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace msm::test {

// x moved by k ulps (towards +inf for k > 0).
inline float ulp_step(float x, int k) {
  for (; k > 0; --k) x = std::nextafter(x, std::numeric_limits<float>::infinity());
  for (; k < 0; ++k) x = std::nextafter(x, -std::numeric_limits<float>::infinity());
  return x;
}

// The perturbations of b (b1..bm) that the range runs over: b itself, the 2^m corners of the box of
// ±ulps (m <= 4; for more moments 2^4 random corners), then `random` vectors of independent integer
// steps in [-ulps, ulps].
inline std::vector<std::vector<float>> perturbations(const std::vector<float>& b, int ulps, int random,
                                                     std::mt19937_64& rng) {
  std::vector<std::vector<float>> out{b};
  const size_t m = b.size();
  const size_t corners = m <= 4 ? (size_t(1) << m) : 16;
  for (size_t c = 0; c < corners; ++c) {
    std::vector<float> p = b;
    uint64_t pattern = m <= 4 ? c : rng();
    for (size_t j = 0; j < m; ++j) p[j] = ulp_step(b[j], (pattern >> j) & 1 ? ulps : -ulps);
    out.push_back(p);
  }
  std::uniform_int_distribution<int> step(-ulps, ulps);
  for (int r = 0; r < random; ++r) {
    std::vector<float> p = b;
    for (size_t j = 0; j < m; ++j) p[j] = ulp_step(b[j], step(rng));
    out.push_back(p);
  }
  return out;
}

struct BoundRange {
  int feasible = 0; // perturbed vectors inside the moment space (b itself among them or not)
  bool input_feasible = false;
  double input_lower = 0.0, input_upper = 0.0; // the bounds of b itself, if input_feasible
  double lower_min = 1.0, lower_max = 0.0, upper_min = 1.0, upper_max = 0.0;

  void add(double lower, double upper) {
    ++feasible;
    lower_min = std::min(lower_min, lower), lower_max = std::max(lower_max, lower);
    upper_min = std::min(upper_min, upper), upper_max = std::max(upper_max, upper);
  }
  // How far v lies outside [min, max] (0 inside); infinite for an empty range.
  static double outside(double v, double lo, double hi) { return v < lo ? lo - v : v > hi ? v - hi : 0.0; }
  double lower_distance(double v) const {
    return feasible ? outside(v, lower_min, lower_max) : std::numeric_limits<double>::infinity();
  }
  double upper_distance(double v) const {
    return feasible ? outside(v, upper_min, upper_max) : std::numeric_limits<double>::infinity();
  }
};

// Sharp Hamburger bounds (JCGT Algorithm 1 in long double, any even m = b.size()) over the
// perturbations of the float vector b = (b1..bm). The upper bound is clamped to 1 (the float
// functions saturate). Where the box straddles the boundary of the moment space (some
// perturbations inside, some outside), the bound is steepest at the boundary itself (B singular:
// the distribution is unique, 2015 Prop. 4), which no sample hits: each segment from an outside
// perturbation to an inside one is bisected (in double, 40 steps) to its last inside point, and
// that point's bounds join the range.
inline BoundRange hamburger_range(const std::vector<float>& b, float zf, int ulps, int random, std::mt19937_64& rng) {
  BoundRange r;
  auto bounds = [&](const std::vector<double>& p) {
    std::vector<double> moments{1.0};
    moments.insert(moments.end(), p.begin(), p.end());
    return oracle::moment_bounds(moments, double(zf));
  };
  std::vector<std::vector<double>> inside, outside;
  bool first = true;
  for (const std::vector<float>& pf : perturbations(b, ulps, random, rng)) {
    std::vector<double> p(pf.begin(), pf.end());
    oracle::MomentBounds o = bounds(p);
    if (o.ok) {
      r.add(o.lower, std::min(o.upper, 1.0));
      if (first) r.input_feasible = true, r.input_lower = o.lower, r.input_upper = std::min(o.upper, 1.0);
      inside.push_back(p);
    } else {
      outside.push_back(p);
    }
    first = false;
  }
  for (size_t k = 0; k < outside.size() && k < 4 && !inside.empty(); ++k) {
    const std::vector<double>& in = inside[k % inside.size()];
    double t_in = 0.0, t_out = 1.0; // position along in -> outside[k]
    std::vector<double> p(in.size());
    for (int step = 0; step < 40; ++step) {
      double t = 0.5 * (t_in + t_out);
      for (size_t j = 0; j < p.size(); ++j) p[j] = in[j] + t * (outside[k][j] - in[j]);
      (bounds(p).ok ? t_in : t_out) = t;
    }
    for (size_t j = 0; j < p.size(); ++j) p[j] = in[j] + t_in * (outside[k][j] - in[j]);
    oracle::MomentBounds o = bounds(p);
    if (o.ok) r.add(o.lower, std::min(o.upper, 1.0));
  }
  return r;
}

// Sharp lower bound over distributions on [lo, hi] (the 2015 LP, solved exactly by GLPK's
// rational re-solve: the simplex tolerances admit wrong distributions when B is nearly singular)
// for one vector: a uniform grid of `points`, then again with 41 points around each atom of the
// first optimum (spacing 1/20 of the grid's), which resolves the atom x of the four-atom optimum
// that the grid misses. A grid can only raise the lower bound; what is left after refinement is
// ~1e-5 (measured against Hausdorff 4MSM on well-conditioned vectors). nullopt-like: feasible =
// false when no distribution on the grid has these moments.
struct LpLower {
  bool feasible = false;
  double lower = 0.0;
};
inline LpLower hausdorff_lp(const std::vector<double>& moments, float zf, double lo, double hi, int points = 501) {
  oracle::LpOptions exact;
  exact.exact = true;
  oracle::Basis basis = oracle::power_basis(int(moments.size()));
  std::vector<double> grid = oracle::uniform_grid(lo, hi, size_t(points));
  oracle::LpBounds first = oracle::lp_bounds(grid, basis, moments, double(zf), exact);
  if (!first.feasible) return {};
  std::vector<double> extra;
  const double h = (hi - lo) / double(points - 1) / 20.0;
  for (double s : first.lower_argmin.support)
    for (int k = -20; k <= 20; ++k)
      if (s + k * h >= lo && s + k * h <= hi) extra.push_back(s + k * h);
  oracle::LpBounds refined = oracle::lp_bounds(oracle::merge_grids(grid, extra), basis, moments, double(zf), exact);
  return {true, refined.feasible ? std::min(refined.lower, first.lower) : first.lower};
}

// The LP's lower bound at the boundary of the moment space between an inside vector and an
// outside one (bisection in double, `steps` LP solves): where the box of a float vector straddles
// the boundary, the bound is steepest there and no corner shows it.
inline LpLower hausdorff_lp_boundary(const std::vector<double>& inside, const std::vector<double>& outside, float zf,
                                     double lo, double hi, int steps = 10) {
  double t_in = 0.0, t_out = 1.0;
  LpLower last = hausdorff_lp(inside, zf, lo, hi);
  std::vector<double> p(inside.size());
  for (int step = 0; step < steps; ++step) {
    double t = 0.5 * (t_in + t_out);
    for (size_t j = 0; j < p.size(); ++j) p[j] = inside[j] + t * (outside[j] - inside[j]);
    LpLower lp = hausdorff_lp(p, zf, lo, hi);
    if (lp.feasible)
      t_in = t, last = lp;
    else
      t_out = t;
  }
  return last;
}

// HPG Eq. (4) in double: the moments (1, b1..b4) that non-linear moments stand for.
inline std::vector<double> nl_moments(double y1, double y2, double v2, double xi4) {
  double v1 = 1.0 - v2;
  return {1.0, v1 * y1 + v2 * y2, v1 * y1 * y1 + v2 * y2 * y2, v1 * y1 * y1 * y1 + v2 * y2 * y2 * y2,
          v1 * y1 * y1 * y1 * y1 + v2 * y2 * y2 * y2 * y2 + xi4};
}

} // namespace msm::test
