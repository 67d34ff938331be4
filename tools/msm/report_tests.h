// The figures of the test suite itself in `msm report`: the suite's test executables (report_suite.h,
// SuiteTests) run with MSM_TEST_FIGURES set, their recorded figures gathered for results.json's
// "tests" (docs/results.schema.json).
#pragma once

#include "report_suite.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace msm::tool {

// The build directory the tests are taken from by default: the one this msm was built in.
std::filesystem::path default_tests_dir();

// Every test executable of the suite exists under `build_dir` and can be run: UsageError naming
// the first that cannot, before any work.
void check_test_executables(const Suite& suite, const std::filesystem::path& build_dir);

// What one gathering gave: the "runs" of results.json's "tests" (each with its exit status and
// figures), and how many runs failed (a test's exit status other than 0).
struct GatheredTests {
  nlohmann::ordered_json runs = nlohmann::ordered_json::array();
  int failed_runs = 0;
};

// Runs each of the suite's test executables with its filter, MSM_TEST_FIGURES naming a file under
// `log_dir` and MSM_DEVICE set to `device` where given; each run's output goes to
// log_dir/<executable>.log. UsageError where a run records no figure (a filter that matches no
// test) or a key is recorded twice.
GatheredTests gather_test_figures(const Suite& suite, const std::filesystem::path& build_dir, const std::string& device,
                                  const std::filesystem::path& log_dir);

} // namespace msm::tool
