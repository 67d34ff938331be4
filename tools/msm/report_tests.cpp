#include "report_tests.h"

#include "commands.h"

#include <fmt/core.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <fstream>
#include <set>
#include <sys/wait.h>
#include <unistd.h>

namespace msm::tool {
namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

// The variable the tests' recorder reads (tests/support/msm/test/figures.h).
constexpr const char* kFiguresVariable = "MSM_TEST_FIGURES";

// Runs the test executable with its filter, the variables set and its output in `log`: its exit
// status (-1 where it could not run or was killed).
int run_test(const fs::path& executable, const std::string& filter, const fs::path& figures, const std::string& device,
             const fs::path& log) {
  const std::string filter_arg = "--gtest_filter=" + filter;
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || ::dup2(fd, 1) < 0 || ::dup2(fd, 2) < 0) std::_Exit(127);
    ::setenv(kFiguresVariable, figures.c_str(), 1);
    if (!device.empty()) ::setenv("MSM_DEVICE", device.c_str(), 1);
    ::execl(executable.c_str(), executable.c_str(), filter_arg.c_str(), static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The figures a run recorded: one JSON object per line.
ordered_json read_figures(const fs::path& file, const std::string& executable) {
  ordered_json figures = ordered_json::array();
  std::ifstream in(file);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    try {
      figures.push_back(ordered_json::parse(line));
    } catch (const nlohmann::json::exception& e) {
      throw UsageError(
          fmt::format("{}: line {} of its figures ({}) is not JSON: {}", executable, number, file.string(), e.what()));
    }
  }
  return figures;
}

} // namespace

fs::path default_tests_dir() { return MSM_BINARY_DIR; }

void check_test_executables(const Suite& suite, const fs::path& build_dir) {
  for (const SuiteTests& t : suite.tests) {
    const fs::path path = build_dir / t.executable;
    if (!fs::is_regular_file(path) || ::access(path.c_str(), X_OK) != 0)
      throw UsageError(
          fmt::format("suite '{}' gathers the figures of the test executable {}, which is not in {} (build "
                      "the tests there, or name the build directory that has them: --tests-from DIR; "
                      "--no-tests leaves them out)",
                      suite.name, t.executable, build_dir.string()));
  }
}

GatheredTests gather_test_figures(const Suite& suite, const fs::path& build_dir, const std::string& device,
                                  const fs::path& log_dir) {
  fs::create_directories(log_dir);
  GatheredTests gathered;
  std::set<std::string> keys;
  for (std::size_t i = 0; i < suite.tests.size(); ++i) {
    const SuiteTests& t = suite.tests[i];
    const std::string stem = fmt::format("{:02}-{}", i, fs::path(t.executable).filename().string());
    const fs::path figures_file = log_dir / (stem + ".figures.jsonl"), log = log_dir / (stem + ".log");
    fs::remove(figures_file);
    fmt::print(stderr, "msm report: tests: {} --gtest_filter={} ...\n", t.executable, t.filter);
    const auto start = std::chrono::steady_clock::now();
    const int status = run_test(build_dir / t.executable, t.filter, fs::absolute(figures_file), device, log);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ordered_json figures = read_figures(figures_file, t.executable);
    if (status != 0) {
      ++gathered.failed_runs;
      fmt::print(stderr, "msm report: tests: {} failed (exit status {}); its output: {}\n", t.executable, status,
                 log.string());
    } else if (figures.empty()) {
      throw UsageError(fmt::format("the test executable {} recorded no figure with the filter {} (does the filter "
                                   "name a test that records figures?); its output: {}",
                                   t.executable, t.filter, log.string()));
    }
    for (const auto& f : figures)
      if (!keys.insert(f.value("key", "")).second)
        throw UsageError(
            fmt::format("the figure {} is recorded twice (the second time by {})", f.value("key", ""), t.executable));
    gathered.runs.push_back({{"title", t.title},
                             {"executable", t.executable},
                             {"filter", t.filter},
                             {"exit_status", status},
                             {"seconds", seconds},
                             {"figures", figures}});
  }
  return gathered;
}

} // namespace msm::tool
