// The outputs of `msm evaluate` (rank 0), each written atomically (temporary name, then rename):
//   results.csv    one row per candidate, by candidate index: its error (the mean over the scenes
//                  of each scene's L1 error over the total radiant power), the error per scene, the
//                  worst fragment, fragments, LPs solved, LP failures, simplex pivots, cold starts.
//                  Deterministic: the same bits for any thread or rank count (no timings in it).
//   ranking.csv    every candidate by error (ties by index; singular bases last), with its rank
//                  among the ranked population and the share of it that does better. The ranked
//                  population is the LP candidates with the most common number of functions (4
//                  where that ties, as the paper's four-function sets): power2 or a closed form
//                  gets the place it would take among the four-function sets.
//   histogram.png  2015 Fig. 4: how many of the ranked population fall into each error interval,
//                  with PCF, VSM, ESM, MSM (power4) and TMSM (trig4) marked where the run has them.
//   summary.json   settings, stacks, the named techniques, the best candidates, timings, LP
//                  throughput per core and rank, and the projected time of the paper's evaluation.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "msm/evaluate/run.h"

namespace msm::evaluate {

// The 2015 paper's evaluation: 392 billion evaluations of its Algorithm 1 (§3.2).
inline constexpr double kPaperLpEvaluations = 392e9;

nlohmann::json summary(const RunResult& run, const RunSettings& settings);
void write_report(const RunResult& run, const RunSettings& settings, const std::filesystem::path& dir);

// The histogram alone (report.cpp draws it; exposed for tests): one bar per bin of the LP
// candidates' errors, marks as (label, error).
struct HistogramMark {
  std::string label;
  double error = 0.0;
};
void write_histogram(const std::filesystem::path& file, const std::vector<double>& errors,
                     const std::vector<HistogramMark>& marks, const std::string& title);

} // namespace msm::evaluate
