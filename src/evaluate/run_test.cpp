// Whole evaluations (run.h) in one process: the result does not depend on the thread count, a run
// cut short resumes from its checkpoint to the same sums (also past a half-written line), another
// run's checkpoint is refused, and the reports are written.
#include "msm/evaluate/run.h"

#include "msm/evaluate/report.h"

#include <gtest/gtest.h>

#include <cstdio>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace msm::evaluate {
namespace {

namespace fs = std::filesystem;

RunSettings small(const fs::path& out, int threads) {
  RunSettings s;
  s.scenes = {"fence", "column"};
  s.stack.size = 32;
  s.stack.grid = 257;
  s.candidates = "named,sample:4:10:3";
  s.out = out;
  s.threads = threads;
  s.fresh = true;
  return s;
}

fs::path scratch(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("msm-evaluate-run-test-" + name);
  fs::remove_all(dir);
  return dir;
}

void expect_same(const RunResult& a, const RunResult& b) {
  ASSERT_EQ(a.results.size(), b.results.size());
  for (std::size_t i = 0; i < a.results.size(); ++i) {
    ASSERT_EQ(a.results[i].scenes.size(), b.results[i].scenes.size());
    for (std::size_t s = 0; s < a.results[i].scenes.size(); ++s) {
      const SceneSums &x = a.results[i].scenes[s], &y = b.results[i].scenes[s];
      EXPECT_EQ(x.error_sum, y.error_sum) << a.candidates[i].name; // bit for bit
      EXPECT_EQ(x.max_error, y.max_error);
      EXPECT_EQ(x.fragments, y.fragments);
      EXPECT_EQ(x.lps, y.lps);
      EXPECT_EQ(x.iterations, y.iterations);
    }
  }
}

TEST(Run, ThreadsDoNotChangeABit) {
  const auto comm = single_process();
  const RunResult one = run_evaluation(small(scratch("one"), 1), *comm);
  const RunResult three = run_evaluation(small(scratch("three"), 3), *comm);
  ASSERT_EQ(one.candidates.size(), 26u);
  expect_same(one, three);
  EXPECT_EQ(one.ranks.size(), 1u);
  EXPECT_GT(one.ranks[0].lps, 0);
}

TEST(Run, ResumesFromItsCheckpoint) {
  const auto comm = single_process();
  const fs::path dir = scratch("resume");
  const RunResult full = run_evaluation(small(dir, 2), *comm);
  // Keep the first 9 lines of the checkpoint and half of the 10th, as a killed run leaves them.
  const fs::path file = dir / "checkpoint" / "rank0.jsonl";
  std::ifstream in(file);
  std::string line, kept;
  for (int k = 0; k < 10 && std::getline(in, line); ++k) kept += k < 9 ? line + "\n" : line.substr(0, line.size() / 2);
  in.close();
  std::ofstream(file, std::ios::trunc) << kept;
  RunSettings again = small(dir, 2);
  again.fresh = false;
  const RunResult resumed = run_evaluation(again, *comm);
  EXPECT_EQ(resumed.resumed, 9);
  EXPECT_EQ(resumed.ranks[0].candidates, 26 - 9);
  expect_same(full, resumed);
  // And the checkpoint file goes on on a fresh line.
  std::ifstream check(file);
  int lines = 0;
  while (std::getline(check, line)) ++lines;
  EXPECT_EQ(lines, 10 + 26 - 9);
}

TEST(Run, RefusesAnotherRunsCheckpoint) {
  const auto comm = single_process();
  const fs::path dir = scratch("other");
  run_evaluation(small(dir, 2), *comm);
  RunSettings other = small(dir, 2);
  other.fresh = false;
  other.stack.grid = 129;
  EXPECT_THROW(run_evaluation(other, *comm), std::invalid_argument);
  other.fresh = true;
  EXPECT_NO_THROW(run_evaluation(other, *comm));
}

TEST(Run, WritesTheReports) {
  const auto comm = single_process();
  const fs::path dir = scratch("report");
  const RunSettings settings = small(dir, 2);
  const RunResult run = run_evaluation(settings, *comm);
  write_report(run, settings, dir);
  for (const char* name : {"results.csv", "ranking.csv", "histogram.png", "summary.json"})
    EXPECT_GT(fs::file_size(dir / name), 100u) << name;
  const nlohmann::json s = summary(run, settings);
  EXPECT_EQ(s["candidates"]["total"], 26);
  EXPECT_EQ(s["candidates"]["lp_failures"], 0);
  // PCF against itself: error 0, rank 1.
  for (const auto& e : s["named"])
    if (e["name"] == "pcf") {
      EXPECT_EQ(e["error"], 0.0);
      EXPECT_EQ(e["lp_rank"], 1);
    }
  // The ranking is sorted by error (names and aliases hold no commas: split on them).
  std::ifstream ranking(dir / "ranking.csv");
  std::string line;
  std::getline(ranking, line);
  double previous = -1.0;
  int rows = 0;
  while (std::getline(ranking, line)) {
    std::vector<std::string> fields;
    for (std::size_t start = 0, end = 0; end != std::string::npos; start = end + 1)
      fields.push_back(line.substr(start, (end = line.find(',', start)) - start));
    const double error = std::stod(fields.at(5));
    EXPECT_GE(error, previous);
    previous = error;
    ++rows;
  }
  EXPECT_EQ(rows, 26);
}

// 2015 §3.2: the power and the trigonometric moments rank among the best of the four-function sets.
// 100 sets drawn from our 37 functions, three built-in scenes at 96 x 96 (measured: trig4 first,
// power4 13th of 102). The full-size run (`msm evaluate`: 1000 sets, six scenes, 128 x 128) ranks
// trig4 3rd, power4 46th of 1002.
TEST(Run, PowerAndTrigonometricMomentsRankHigh) {
  const auto comm = single_process();
  RunSettings s;
  s.scenes = {"fence", "stair", "column"};
  s.stack.size = 96;
  s.stack.grid = 1025;
  s.candidates = "power4,trig4,sample:4:100:11";
  s.out = scratch("rank");
  s.fresh = true;
  const RunResult run = run_evaluation(s, *comm);
  ASSERT_EQ(run.results.size(), 102u);
  const auto rank = [&](std::size_t index) {
    int better = 0;
    for (const CandidateResult& r : run.results) better += r.error() < run.results[index].error() ? 1 : 0;
    return better + 1;
  };
  EXPECT_LE(rank(1), 5) << "trig4";   // the best 5%
  EXPECT_LE(rank(0), 20) << "power4"; // the best 20%
  // LPs that neither GridLp nor GLPK solve count as leaking (run.h); they must stay rare: 5 of
  // 2.5e5 LPs here with the view-fitted stacks, 126 of 1.1e7 in the full-size run. Allowed: 1 in
  // 10^4 of the LPs, and at most one per candidate.
  std::int64_t lps = 0, failures = 0;
  for (const CandidateResult& r : run.results) {
    lps += r.lps(), failures += r.failures();
    EXPECT_LE(r.failures(), 1) << "candidate " << r.index;
  }
  std::printf("%lld LPs, %lld unsolved\n", static_cast<long long>(lps), static_cast<long long>(failures));
  EXPECT_LE(failures * 10000, lps);
}

} // namespace
} // namespace msm::evaluate
