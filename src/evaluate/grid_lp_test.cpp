// The fast grid LP (grid_lp.h) against GLPK's exact mode (msm::oracle::lp_bounds with
// LpOptions::exact: rational arithmetic, no simplex tolerances) on random bases of the 37 candidate
// functions and random distributions on the grid, cold and warm started.
#include "msm/evaluate/grid_lp.h"

#include "msm/evaluate/functions.h"
#include "msm/oracle/lp_oracle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <set>
#include <vector>

namespace msm::evaluate {
namespace {

std::vector<std::function<double(double)>> functions_of(const std::vector<int>& indices) {
  std::vector<std::function<double(double)>> f;
  f.reserve(indices.size());
  for (int i : indices) f.emplace_back(candidate_functions()[i].value);
  return f;
}

std::vector<int> random_functions(std::mt19937& rng, int m) {
  std::vector<int> all(kFunctionCount);
  for (int i = 0; i < kFunctionCount; ++i) all[i] = i;
  std::shuffle(all.begin(), all.end(), rng);
  all.resize(m);
  return all;
}

// 1..max_atoms atoms on distinct grid points, Dirichlet(1) weights; half of the time clustered in
// a window of 40 points (like the depths of one filter kernel), else anywhere.
std::vector<GridAtom> random_distribution(std::mt19937& rng, int n, int max_atoms) {
  const int atoms = std::uniform_int_distribution<int>(1, max_atoms)(rng);
  const bool clustered = std::uniform_int_distribution<int>(0, 1)(rng) == 1;
  const int lo = clustered ? std::uniform_int_distribution<int>(0, n - 41)(rng) : 0;
  const int hi = clustered ? lo + 40 : n - 1;
  std::set<int> points;
  while (int(points.size()) < atoms) points.insert(std::uniform_int_distribution<int>(lo, hi)(rng));
  std::vector<GridAtom> z;
  double total = 0.0;
  for (int p : points) {
    const double w = -std::log(std::uniform_real_distribution<double>(1e-12, 1.0)(rng));
    z.push_back({p, w});
    total += w;
  }
  for (GridAtom& a : z) a.weight /= total;
  return z;
}

// GLPK's exact lower bound, or nothing where GLPK finds the moments infeasible (moments of one to
// three grid points lie on the boundary of the grid's moment cone, and rounding b to double can
// move them outside: GLPK's exact mode then says "infeasible", LpOptions::rounding_band
// notwithstanding).
std::optional<double> oracle_lower(const std::vector<double>& grid, const std::vector<int>& functions,
                                   const std::vector<GridAtom>& z, int cutoff) {
  oracle::Basis basis = oracle::custom_basis("test", functions_of(functions));
  std::vector<double> b(functions.size(), 0.0);
  for (const GridAtom& a : z)
    for (std::size_t j = 0; j < functions.size(); ++j)
      b[j] += a.weight * candidate_functions()[functions[j]].value(grid[a.index]);
  oracle::LpOptions options;
  options.exact = true;
  const oracle::LpBounds bounds = oracle::lp_bounds(grid, basis, b, grid[cutoff], options);
  if (!bounds.feasible) return std::nullopt;
  return bounds.lower;
}

// The bound is a probability of the distribution's own support too: it never exceeds PCF.
double pcf(const std::vector<GridAtom>& z, int cutoff) {
  double sum = 0.0;
  for (const GridAtom& a : z) sum += a.index < cutoff ? a.weight : 0.0;
  return sum;
}

TEST(GridLp, AgreesWithGlpkExactOnRandomInputs) {
  std::mt19937 rng(16);
  const std::vector<double> grid = oracle::uniform_grid(0.0, 1.0, 129);
  const int n = int(grid.size());
  double worst = 0.0;
  int cases = 0, moved_inside = 0;
  for (int trial = 0; trial < 160; ++trial) {
    const int m = std::uniform_int_distribution<int>(2, 6)(rng);
    const std::vector<int> functions = random_functions(rng, m);
    const GridBasis basis(grid, functions_of(functions), "random");
    GridLp lp(basis);
    std::vector<GridAtom> z = random_distribution(rng, n, trial % 3 == 0 ? 3 : 30);
    const int cutoff = std::uniform_int_distribution<int>(1, n - 1)(rng);
    std::optional<double> exact = oracle_lower(grid, functions, z, cutoff);
    // Where GLPK cannot take the moments (on the boundary, and for some bases with exp(20 z) also
    // inside, where its simplex reports infeasibility before the exact phase), both solvers get
    // them moved inside the cone, mixing in more and more of the uniform distribution on the grid.
    const std::vector<GridAtom> original = z;
    for (double share : {1e-6, 1e-3, 1e-2, 1e-1}) {
      if (exact) break;
      z = original;
      for (GridAtom& a : z) a.weight *= 1.0 - share;
      for (int i = 0; i < n; ++i) z.push_back({i, share / n});
      exact = oracle_lower(grid, functions, z, cutoff);
      ++moved_inside;
    }
    ASSERT_TRUE(exact.has_value()) << "trial " << trial;
    std::vector<double> t(basis.rows());
    basis.moments(z, t);
    const LpResult mine = lp.minimize(t, cutoff, z);
    ASSERT_TRUE(mine.solved) << "trial " << trial;
    const double error = std::fabs(mine.value - *exact);
    worst = std::max(worst, error);
    EXPECT_LE(error, 1e-7) << "trial " << trial << ", m = " << m << ", cutoff " << cutoff << ": " << mine.value
                           << " vs GLPK exact " << *exact;
    EXPECT_LE(mine.value, pcf(z, cutoff) + 1e-9);
    ++cases;
  }
  std::printf(
      "%d cases (%d retries with moments moved inside the cone for GLPK), largest difference to GLPK exact %.2e\n",
      cases, moved_inside, worst);
}

// A chain of related LPs (one distribution moving along the grid, several cutoffs per step, as the
// fragments of neighbouring texels and their layers) warm started gives the cold results. Random
// bases of six functions can be nearly dependent (the independence of GridBasis down to 1e-3):
// there a few LPs may find no solution (reported as such, never a wrong value), at most 2%.
TEST(GridLp, WarmStartsGiveTheColdResults) {
  std::mt19937 rng(7);
  const std::vector<double> grid = oracle::uniform_grid(0.0, 1.0, 513);
  const int n = int(grid.size());
  int solves = 0, unsolved = 0;
  for (int chain = 0; chain < 6; ++chain) {
    const std::vector<int> functions = random_functions(rng, chain % 2 ? 4 : 6);
    const GridBasis basis(grid, functions_of(functions), "chain");
    GridLp warm_lp(basis), cold_lp(basis);
    WarmStart warm;
    std::vector<GridAtom> z = random_distribution(rng, n - 60, 20);
    for (int step = 0; step < 60; ++step) {
      for (GridAtom& a : z)
        if (std::uniform_int_distribution<int>(0, 3)(rng) == 0) a.index = std::min(a.index + 1, n - 1);
      std::vector<double> t(basis.rows());
      basis.moments(z, t);
      for (int layer = 0; layer < 3; ++layer) {
        const int cutoff = std::uniform_int_distribution<int>(1, n - 1)(rng);
        const LpResult a = warm_lp.minimize(t, cutoff, z, &warm);
        const LpResult b = cold_lp.minimize(t, cutoff, z);
        ++solves;
        if (!a.solved || !b.solved) {
          EXPECT_LT(basis.independence(), 1e-2) << "chain " << chain << ": unsolved LP of a well-conditioned basis";
          ++unsolved;
          continue;
        }
        EXPECT_NEAR(a.value, b.value, 1e-8) << "chain " << chain << " step " << step;
        EXPECT_LE(a.value, pcf(z, cutoff) + 1e-9);
      }
    }
  }
  EXPECT_LE(unsolved, solves / 50);
  std::printf("%d LPs, %d without a solution\n", solves, unsolved);
}

// Moments of a single grid point lie on the boundary of the moment cone: the LP is degenerate
// (the only feasible point is the Dirac itself), and the bound is its step, exactly. (Not at z = 0
// for the trigonometric functions: there z = 1 has the same moments, so the bound is 0.)
TEST(GridLp, DiracsGiveTheirStep) {
  const std::vector<double> grid = oracle::uniform_grid(0.0, 1.0, 1025);
  for (const std::vector<int>& functions : std::vector<std::vector<int>>{{0, 1, 2, 3}, {8, 9, 12, 13}, {0, 1}}) {
    const GridBasis basis(grid, functions_of(functions), "dirac");
    GridLp lp(basis);
    WarmStart warm;
    for (int index : {0, 1, 300, 512, 1023, 1024}) {
      if (functions[0] == 8 && (index == 0 || index == 1024)) continue;
      const std::vector<GridAtom> z{{index, 1.0}};
      std::vector<double> t(basis.rows());
      basis.moments(z, t);
      for (int cutoff : {index - 1, index, index + 1}) {
        if (cutoff < 0 || cutoff > 1025) continue;
        const LpResult r = lp.minimize(t, cutoff, z, &warm);
        ASSERT_TRUE(r.solved);
        EXPECT_NEAR(r.value, index < cutoff ? 1.0 : 0.0, 1e-9) << "index " << index << " cutoff " << cutoff;
      }
    }
  }
}

TEST(GridBasis, RejectsDependentFunctions) {
  const std::vector<double> grid = oracle::uniform_grid(0.0, 1.0, 257);
  // z and 2z + 1 are dependent with the constant.
  std::vector<std::function<double(double)>> dependent{[](double z) { return z; }, [](double z) { return 2 * z + 1; }};
  EXPECT_THROW(GridBasis(grid, dependent, "dependent"), SingularBasis);
  // 1/(1+z) and z/(1+z) = 1 - 1/(1+z) likewise.
  std::vector<std::function<double(double)>> rational{[](double z) { return 1 / (1 + z); },
                                                      [](double z) { return z / (1 + z); }};
  EXPECT_THROW(GridBasis(grid, rational, "rational"), SingularBasis);
  // Five functions on four points cannot be independent.
  EXPECT_THROW(GridBasis(oracle::uniform_grid(0.0, 1.0, 4), functions_of({0, 1, 2, 3, 4}), "few points"),
               SingularBasis);
}

} // namespace
} // namespace msm::evaluate
