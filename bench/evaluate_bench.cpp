// LP evaluations per second per core of `msm evaluate` (msm::evaluate::GridLp): every fragment of
// a real depth-peeled stack (the built-in fence scene, 256 x 256 texels, the 1025-point depth grid)
// that needs the LP, for the power moments, the trigonometric moments and four-function candidates
// drawn from the 37, with the warm starts of the evaluation (one chain per layer, scan order) and,
// for comparison, each LP cold. GLPK (msm::oracle::lp_bounds) on a sample of the same LPs gives
// the general solver's rate. One thread: the rate per core.
#include "msm/evaluate/evaluate.h"
#include "msm/evaluate/functions.h"
#include "msm/oracle/lp_oracle.h"
#include "msm/scene/scene.h"

#include <benchmark/benchmark.h>

#include <functional>
#include <vector>

namespace {

using namespace msm::evaluate;

const Stack& fence() {
  static const Stack stack = [] {
    StackSettings s;
    s.size = 256;
    s.grid = 1025;
    return build_stack("fence", msm::scene::builtin_scene("fence"), s);
  }();
  return stack;
}

// The fragments that go through the LP in the evaluation: counted and not fully lit.
std::vector<const Fragment*> lp_fragments() {
  std::vector<const Fragment*> list;
  for (const Fragment& f : fence().fragments)
    if (f.counted && f.pcf > 0.0) list.push_back(&f);
  return list;
}

const char* kCandidates[] = {"power4", "trig4", "exp2+log4+rat1+atan4", "z+sin6pi+expm10+bump", "power6"};

// The evaluation itself (warm starts), per candidate; items = LPs.
void BM_EvaluateWarm(benchmark::State& state) {
  const Candidate candidate = parse_candidates(kCandidates[state.range(0)]).at(0);
  const GridBasis basis = prepare_basis(candidate, fence().settings.grid);
  std::int64_t lps = 0, failures = 0;
  for (auto _ : state) {
    const SceneSums sums = evaluate(fence(), candidate, &basis);
    lps += sums.lps;
    failures += sums.failures;
    benchmark::DoNotOptimize(sums.error_sum);
  }
  state.SetItemsProcessed(lps);
  state.counters["failures"] = double(failures);
  state.SetLabel(candidate.name);
}
BENCHMARK(BM_EvaluateWarm)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

// The same LPs, each from scratch.
void BM_EvaluateCold(benchmark::State& state) {
  const Candidate candidate = parse_candidates(kCandidates[state.range(0)]).at(0);
  const GridBasis basis = prepare_basis(candidate, fence().settings.grid);
  GridLp lp(basis);
  const std::vector<const Fragment*> fragments = lp_fragments();
  std::vector<double> t(std::size_t(basis.rows()));
  std::int64_t lps = 0;
  for (auto _ : state) {
    for (const Fragment* f : fragments) {
      basis.moments(fence().kernel(f->texel), t);
      benchmark::DoNotOptimize(lp.minimize(t, f->cutoff, fence().kernel(f->texel)).value);
    }
    lps += std::int64_t(fragments.size());
  }
  state.SetItemsProcessed(lps);
  state.SetLabel(candidate.name);
}
BENCHMARK(BM_EvaluateCold)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

// GLPK on every 20th of those LPs (power4, simplex in double, the oracle's defaults).
void BM_Glpk(benchmark::State& state) {
  const std::vector<double> grid = unit_grid(fence().settings.grid);
  const msm::oracle::Basis basis = msm::oracle::power_basis(4);
  const std::vector<const Fragment*> all = lp_fragments();
  std::vector<const Fragment*> fragments;
  for (std::size_t i = 0; i < all.size(); i += 20) fragments.push_back(all[i]);
  std::int64_t lps = 0;
  for (auto _ : state) {
    for (const Fragment* f : fragments) {
      std::vector<double> b(4, 0.0);
      for (const GridAtom& a : fence().kernel(f->texel)) {
        const double z = grid[a.index];
        b[0] += a.weight * z, b[1] += a.weight * z * z, b[2] += a.weight * z * z * z, b[3] += a.weight * z * z * z * z;
      }
      const double zf = f->cutoff < int(grid.size()) ? grid[f->cutoff] : 2.0;
      benchmark::DoNotOptimize(msm::oracle::lp_bounds(grid, basis, b, zf).lower);
    }
    lps += std::int64_t(fragments.size());
  }
  state.SetItemsProcessed(lps);
}
BENCHMARK(BM_Glpk)->Unit(benchmark::kMillisecond);

} // namespace
