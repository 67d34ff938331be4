// The error term of one candidate on one stack (evaluate.h).
#include "msm/evaluate/evaluate.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>

#include "msm/baselines.h"
#include "msm/bias.h"
#include "msm/config.h"
#include "msm/evaluate/functions.h"
#include "msm/hamburger4.h"
#include "msm/hausdorff4.h"
#include "msm/moments.h"
#include "msm/oracle/lp_oracle.h"
#include "msm/trigonometric.h"

namespace msm::evaluate {

std::vector<double> unit_grid(int n) {
  std::vector<double> grid(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) grid[i] = double(i) / double(n - 1);
  return grid;
}

GridBasis prepare_basis(const Candidate& candidate, int grid_points) {
  if (candidate.technique != Technique::lp) throw std::invalid_argument("prepare_basis: not an LP candidate");
  std::vector<std::function<double(double)>> functions;
  functions.reserve(candidate.functions.size());
  for (int f : candidate.functions) functions.emplace_back(candidate_functions()[f].value);
  return GridBasis(unit_grid(grid_points), functions, candidate.name);
}

namespace {

// E_Z of a generation function of include/msm (float per atom, summed in double).
template <typename Value, int N, typename Generate>
std::array<double, N> expectation(std::span<const GridAtom> kernel, double steps, Generate generate) {
  std::array<double, N> sum{};
  for (const GridAtom& a : kernel) {
    const Value v = generate(float(double(a.index) / steps));
    for (int j = 0; j < N; ++j) sum[j] += a.weight * double(v[j]);
  }
  return sum;
}

vec4 to_vec4(const std::array<double, 4>& b) { return vec4(float(b[0]), float(b[1]), float(b[2]), float(b[3])); }
vec2 to_vec2(const std::array<double, 2>& b) { return vec2(float(b[0]), float(b[1])); }

// The same LP by GLPK (the oracle), for the few that GridLp cannot solve.
std::optional<double> glpk_bound(const Candidate& candidate, const std::vector<double>& grid,
                                 std::span<const GridAtom> kernel, int cutoff) {
  const int n = int(grid.size());
  if (cutoff >= n) return 1.0; // every grid point counts
  std::vector<std::function<double(double)>> functions;
  functions.reserve(candidate.functions.size());
  for (int f : candidate.functions) functions.emplace_back(candidate_functions()[f].value);
  const oracle::Basis basis = oracle::custom_basis(candidate.name, functions);
  std::vector<double> b(functions.size(), 0.0);
  for (const GridAtom& a : kernel)
    for (std::size_t j = 0; j < functions.size(); ++j) b[j] += a.weight * functions[j](grid[a.index]);
  const oracle::LpBounds bounds = oracle::lp_bounds(grid, basis, b, grid[std::max(cutoff, 0)]);
  if (!bounds.feasible) return std::nullopt;
  return std::clamp(bounds.lower, 0.0, 1.0);
}

} // namespace

double closed_form_shadow(Technique technique, std::span<const GridAtom> kernel, double zf, int grid_points) {
  const double steps = double(grid_points - 1);
  const float z = float(zf);
  float shadow = 0.0f;
  switch (technique) {
  case Technique::lp: throw std::invalid_argument("closed_form_shadow: an LP candidate has no closed form");
  case Technique::pcf: {
    double sum = 0.0;
    for (const GridAtom& a : kernel) sum += double(a.index) / steps < zf ? a.weight : 0.0;
    return std::min(sum, 1.0);
  }
  case Technique::vsm:
    shadow =
        msm_vsm_shadow(to_vec2(expectation<vec2, 2>(kernel, steps, [](float d) { return msm_vsm_moments(d); })), z);
    break;
  case Technique::esm: {
    const auto b =
        expectation<vec2, 1>(kernel, steps, [](float d) { return vec2(msm_esm_moment(d, MSM_ESM_C_DEFAULT)); });
    shadow = msm_esm_shadow(float(b[0]), z, MSM_ESM_C_DEFAULT);
    break;
  }
  case Technique::evsm2: {
    const auto b = expectation<vec2, 2>(
        kernel, steps, [](float d) { return msm_evsm2_moments(msm_signed_depth(d), MSM_EVSM_C_POS_128BIT); });
    shadow = msm_evsm2_shadow(to_vec2(b), msm_signed_depth(z), MSM_EVSM_C_POS_128BIT, MSM_EVSM_MIN_VARIANCE_FLOAT);
    break;
  }
  case Technique::evsm4: {
    const auto b = expectation<vec4, 4>(kernel, steps, [](float d) {
      return msm_evsm4_moments(msm_signed_depth(d), MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT);
    });
    shadow = msm_evsm4_shadow(to_vec4(b), msm_signed_depth(z), MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT,
                              MSM_EVSM_MIN_VARIANCE_FLOAT);
    break;
  }
  case Technique::hamburger4:
  case Technique::hausdorff4: {
    const vec4 b = msm_apply_bias(to_vec4(expectation<vec4, 4>(kernel, steps, [](float d) { return msm_moments4(d); })),
                                  msm_moment_bias(MSM_REP_UNIT_FLOAT));
    shadow = technique == Technique::hamburger4 ? msm_hamburger4_lower(b, z) : msm_hausdorff4_lower(b, z, 0.0f, 1.0f);
    break;
  }
  case Technique::tmsm:
    shadow = msm_trig_lower(
        msm_trig_bias(to_vec4(expectation<vec4, 4>(kernel, steps, [](float d) { return msm_trig_moments(d); }))), z);
    break;
  }
  return std::isfinite(shadow) ? std::clamp(double(shadow), 0.0, 1.0) : 0.0;
}

SceneSums evaluate(const Stack& stack, const Candidate& candidate, const GridBasis* basis,
                   const EvaluateOptions& options) {
  SceneSums sums;
  const auto add = [&](double shadow, const Fragment& f) {
    const double error = std::fabs(shadow - f.pcf);
    sums.error_sum += error;
    sums.max_error = std::max(sums.max_error, error);
    ++sums.fragments;
  };
  if (candidate.technique != Technique::lp) {
    for (const Fragment& f : stack.fragments)
      if (f.counted)
        add(candidate.technique == Technique::pcf
                ? f.pcf
                : closed_form_shadow(candidate.technique, stack.kernel(f.texel), f.receiver, stack.settings.grid),
            f);
    return sums;
  }
  if (!basis || basis->columns() != stack.settings.grid)
    throw std::invalid_argument("evaluate: an LP candidate needs its basis on the stack's grid");
  GridLp lp(*basis);
  std::vector<WarmStart> warm(static_cast<std::size_t>(stack.settings.max_layers));
  std::array<double, kMaxRows> moments{};
  const std::span<double> t(moments.data(), std::size_t(basis->rows()));
  std::int32_t moments_of = -1;
  for (const Fragment& f : stack.fragments) {
    if (!f.counted) continue;
    if (f.pcf == 0.0 && !options.solve_lit) {
      add(0.0, f); // the bound lies in [0, PCF] = {0}
      continue;
    }
    if (f.texel != moments_of) {
      basis->moments(stack.kernel(f.texel), t);
      moments_of = f.texel;
    }
    const LpResult r = lp.minimize(t, f.cutoff, stack.kernel(f.texel), &warm[std::size_t(f.layer)]);
    ++sums.lps;
    sums.iterations += r.iterations;
    sums.cold += r.cold ? 1 : 0;
    double shadow = r.value;
    if (!r.solved) {
      const std::optional<double> fallback =
          options.glpk_fallback ? glpk_bound(candidate, basis->grid(), stack.kernel(f.texel), f.cutoff) : std::nullopt;
      if (fallback) {
        ++sums.fallbacks;
        shadow = *fallback;
      } else {
        ++sums.failures;
        shadow = 0.0;
      }
    }
    add(shadow, f);
  }
  return sums;
}

} // namespace msm::evaluate
