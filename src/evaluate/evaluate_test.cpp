// The error term (evaluate.h) on real stacks: the LP bound against the closed forms of include/msm
// where they exist, the lower-bound property, the exact treatment of lit fragments, and 2015 Fig. 3's
// ordering of m = 2, 3, 4 on built-in scenes.
#include "msm/evaluate/evaluate.h"

#include "msm/baselines.h"
#include "msm/evaluate/functions.h"
#include "msm/hamburger4.h"
#include "msm/scene/scene.h"
#include "msm/trigonometric.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace msm::evaluate {
namespace {

StackSettings settings(int size, int grid) {
  StackSettings s;
  s.size = size;
  s.grid = grid;
  return s;
}

struct Stats {
  std::vector<double> differences;
  std::size_t unsolved = 0; // LPs GridLp gave up on (msm evaluate hands those to GLPK)
  void add(double d) {
    if (std::isnan(d))
      ++unsolved;
    else
      differences.push_back(std::fabs(d));
  }
  double quantile(double q) {
    std::sort(differences.begin(), differences.end());
    return differences.empty() ? 0.0 : differences[std::size_t(q * double(differences.size() - 1))];
  }
  double mean() const {
    double s = 0.0;
    for (double d : differences) s += d;
    return differences.empty() ? 0.0 : s / double(differences.size());
  }
};

// The grid of the stack (unit indices 0..n-1) with points added below 0 (and above 1) at steps
// growing by 5% from the grid spacing up to `reach`: a finite stand-in for I = R around [0, 1].
// Returns the grid and the index of unit point 0 in it.
std::pair<std::vector<double>, int> extended_grid(int n, double reach_below, double reach_above) {
  std::vector<double> below, above;
  const double h = 1.0 / double(n - 1);
  for (double step = h, z = 0.0; z > -reach_below;) step *= 1.05, z -= step, below.push_back(z);
  for (double step = h, z = 1.0; z < 1.0 + reach_above;) step *= 1.05, z += step, above.push_back(z);
  std::vector<double> grid(below.rbegin(), below.rend());
  const int offset = int(grid.size());
  const std::vector<double> unit = unit_grid(n);
  grid.insert(grid.end(), unit.begin(), unit.end());
  grid.insert(grid.end(), above.begin(), above.end());
  return {grid, offset};
}

GridBasis basis_on(const std::vector<double>& grid, std::vector<std::function<double(double)>> functions) {
  return GridBasis(grid, functions, "cross-check");
}

std::vector<std::function<double(double)>> named_functions(std::initializer_list<const char*> names) {
  std::vector<std::function<double(double)>> f;
  for (const char* name : names) f.emplace_back(candidate_functions()[*find_function(name)].value);
  return f;
}

// The 2015 Problem 1 on a grid for a distribution given on the stack's grid, shifted by `offset`
// into `basis`'s grid, plus extra atoms (a bias), at the cutoff `cutoff` of the stack's grid.
double lp_bound(const GridBasis& basis, int offset, std::span<const GridAtom> kernel, double keep,
                const std::vector<GridAtom>& extra, int cutoff) {
  std::vector<GridAtom> z;
  for (const GridAtom& a : kernel) z.push_back({a.index + offset, keep * a.weight});
  z.insert(z.end(), extra.begin(), extra.end());
  std::vector<double> t(basis.rows());
  basis.moments(z, t);
  GridLp lp(basis);
  const LpResult r = lp.minimize(t, cutoff + offset, z);
  return r.solved ? r.value : std::numeric_limits<double>::quiet_NaN(); // counted by Stats
}

// The check of the issue: on the fragments of a real stack (fence and stair), the LP bound equals
// the closed forms of include/msm within the tolerance of the grid (atoms restricted to grid points,
// so the LP's bound lies above the continuous one) and of the closed forms' float arithmetic (their
// worst case is the nearly singular moments of kernels holding one or two depths). Each closed form
// gets the LP's problem: zf at the grid point the LP's cutoff stands for, the same bias in the
// moments, and the interval the closed form assumes (I = R for Hamburger 4MSM, VSM and ESM,
// stood in for by a grid extended below 0 and above 1; [0, 1] for Hausdorff 4MSM; the circle for
// TMSM).
TEST(ClosedForms, TheLpBoundEqualsThemOnARealStack) {
  const int n = 1025;
  const auto [wide, wide_offset] = extended_grid(n, 12.0, 12.0);
  const auto [left, left_offset] = extended_grid(n, 2.0, 0.0);
  const std::vector<double> unit = unit_grid(n);
  const GridBasis hamburger = basis_on(wide, named_functions({"z", "z2", "z3", "z4"}));
  const GridBasis hausdorff = basis_on(unit, named_functions({"z", "z2", "z3", "z4"}));
  const GridBasis trig = basis_on(unit, named_functions({"sin2pi", "cos2pi", "sin4pi", "cos4pi"}));
  const GridBasis vsm = basis_on(wide, named_functions({"z", "z2"}));
  const float c = 20.0f; // ESM's exponent here: exp(c z) over [-2, 1] keeps its information in double
  const GridBasis esm = basis_on(left, {[c](double z) { return std::exp(double(c) * z); }});
  const float alpha = MSM_ALPHA_UNIT_FLOAT;
  const std::vector<GridAtom> power_bias{{0, alpha / 2}, {n - 1, alpha / 2}}; // b* = E(½δ0 + ½δ1)
  std::vector<GridAtom> uniform_bias;                                         // trigonometric b* = 0
  for (int i = 0; i < n - 1; ++i) uniform_bias.push_back({i, double(MSM_TRIG_ALPHA_DEFAULT) / (n - 1)});

  Stats s_hamburger, s_hausdorff, s_trig, s_vsm, s_esm;
  for (const char* name : {"fence", "stair"}) {
    const Stack stack = build_stack(name, scene::builtin_scene(name), settings(40, n));
    for (const Fragment& f : stack.fragments) {
      if (!f.counted || f.cutoff <= 0 || f.cutoff >= n) continue;
      const auto kernel = stack.kernel(f.texel);
      const float zf = float(double(f.cutoff) / double(n - 1)); // the LP's cutoff as a depth
      const double closed_hamburger = closed_form_shadow(Technique::hamburger4, kernel, zf, n);
      std::vector<GridAtom> shifted_bias = power_bias;
      for (GridAtom& a : shifted_bias) a.index += wide_offset;
      s_hamburger.add(closed_hamburger - lp_bound(hamburger, wide_offset, kernel, 1.0 - alpha, shifted_bias, f.cutoff));
      s_hausdorff.add(closed_form_shadow(Technique::hausdorff4, kernel, zf, n) -
                      lp_bound(hausdorff, 0, kernel, 1.0 - alpha, power_bias, f.cutoff));
      s_trig.add(closed_form_shadow(Technique::tmsm, kernel, zf, n) -
                 lp_bound(trig, 0, kernel, 1.0 - MSM_TRIG_ALPHA_DEFAULT, uniform_bias, f.cutoff));
      // VSM and ESM straight from their headers, unbiased, with the minimum variance far below the
      // grid's resolution (the closed form's own clamp is a float safeguard, not the bound).
      double b1 = 0, b2 = 0, e = 0;
      for (const GridAtom& a : kernel) {
        const double z = double(a.index) / (n - 1);
        b1 += a.weight * z, b2 += a.weight * z * z, e += a.weight * double(msm_esm_moment(float(z), c));
      }
      s_vsm.add(double(msm_vsm_shadow(vec2(float(b1), float(b2)), zf, 1e-9f)) -
                lp_bound(vsm, wide_offset, kernel, 1.0, {}, f.cutoff));
      s_esm.add(double(msm_esm_shadow(float(e), zf, c)) - lp_bound(esm, left_offset, kernel, 1.0, {}, f.cutoff));
    }
  }
  const auto report = [](const char* name, Stats& s) {
    std::printf("%-11s %zu fragments (%zu LPs unsolved): |closed form - LP| mean %.2e, p90 %.2e, p99 %.2e, "
                "max %.2e\n",
                name, s.differences.size(), s.unsolved, s.mean(), s.quantile(0.9), s.quantile(0.99), s.quantile(1.0));
  };
  // Tolerances: the closed forms' float error, documented in their headers as p99 ~5e-6 and worst
  // ~1e-3 next to nearly singular moments (trigonometric.h), plus the grid, which can only raise the
  // LP's bound where the continuous optimum's atoms fall between grid points. Measured (fence and
  // stair at 40x40, the view-fitted framing): mean <= 2.7e-6, p99 <= 7.5e-5, max <= 5.5e-4 (before
  // that framing: 1.2e-6, 3.3e-5, 1.5e-4).
  for (auto [name, stats] : {std::pair{"hamburger4", &s_hamburger}, std::pair{"hausdorff4", &s_hausdorff},
                             std::pair{"tmsm", &s_trig}, std::pair{"vsm", &s_vsm}, std::pair{"esm", &s_esm}}) {
    report(name, *stats);
    ASSERT_GT(stats->differences.size(), 1500u) << name;
    // GridLp without a warm start gives up on a few of Hamburger's LPs on the grid stretched to
    // [-12, 13] (z^4 spans 8 decades there): 6 of 2368 measured with the view-fitted framing, 0 of
    // 1823 before it. msm evaluate solves those with GLPK (EvaluateSums::fallbacks); here they may
    // not exceed 1%.
    EXPECT_LE(stats->unsolved * 100, stats->differences.size()) << name;
    EXPECT_LE(stats->mean(), 1e-5) << name;
    EXPECT_LE(stats->quantile(0.99), 2e-4) << name;
    EXPECT_LE(stats->quantile(1.0), 2e-3) << name;
  }
}

// A lower bound: the LP's shadow never exceeds PCF, so the error is the light leaking PCF - G; and
// the fully lit fragments, whose LP the evaluation skips, have the bound 0 (checked by solving them).
TEST(Evaluate, LowerBoundAndLitFragments) {
  const Stack stack = build_stack("stair", scene::builtin_scene("stair"), settings(48, 513));
  for (const char* spec : {"power4", "trig4", "exp2+log4+rat1+atan4"}) {
    const Candidate candidate = parse_candidates(spec).at(0);
    const GridBasis basis = prepare_basis(candidate, 513);
    EvaluateOptions all;
    all.solve_lit = true;
    const SceneSums skipped = evaluate(stack, candidate, &basis), solved = evaluate(stack, candidate, &basis, all);
    EXPECT_EQ(skipped.fragments, solved.fragments);
    EXPECT_GT(solved.lps, skipped.lps);
    EXPECT_EQ(skipped.failures + solved.failures, 0) << spec;
    EXPECT_NEAR(skipped.error_sum, solved.error_sum, 1e-7 * double(solved.fragments)) << spec;
    // Every fragment's bound against its PCF.
    GridLp lp(basis);
    std::vector<double> t(basis.rows());
    for (const Fragment& f : stack.fragments) {
      if (!f.counted) continue;
      basis.moments(stack.kernel(f.texel), t);
      const LpResult r = lp.minimize(t, f.cutoff, stack.kernel(f.texel));
      ASSERT_TRUE(r.solved);
      EXPECT_LE(r.value, f.pcf + 1e-9) << spec;
      if (f.pcf == 0.0) { EXPECT_LE(r.value, 1e-9) << spec; }
    }
  }
}

// 2015 Fig. 3: four functions do better than three, three better than two, for the power and the
// trigonometric moments, on built-in scenes (and six better than four).
TEST(Evaluate, MoreMomentsLeakLess) {
  for (const char* scene_name : {"fence", "stair", "column"}) {
    const Stack stack = build_stack(scene_name, scene::builtin_scene(scene_name), settings(128, 1025));
    for (const char* family : {"power", "trig"}) {
      std::vector<double> errors;
      for (int m : {2, 3, 4, 6}) {
        const Candidate candidate = parse_candidates(std::string(family) + std::to_string(m)).at(0);
        const GridBasis basis = prepare_basis(candidate, 1025);
        const SceneSums sums = evaluate(stack, candidate, &basis);
        // m = 6 has a few LPs that neither GridLp nor GLPK solves (grid_lp.h): counted as leaking.
        if (m <= 4) {
          EXPECT_EQ(sums.failures, 0) << scene_name << " " << family << m;
        } else {
          EXPECT_LE(sums.failures, sums.lps / 100) << scene_name << " " << family << m;
        }
        errors.push_back(sums.error());
      }
      std::printf("%-7s %-5s m = 2, 3, 4, 6: %.4f%% %.4f%% %.4f%% %.4f%%\n", scene_name, family, 100 * errors[0],
                  100 * errors[1], 100 * errors[2], 100 * errors[3]);
      for (std::size_t k = 1; k < errors.size(); ++k)
        EXPECT_LT(errors[k], errors[k - 1]) << scene_name << " " << family;
    }
  }
}

} // namespace
} // namespace msm::evaluate
