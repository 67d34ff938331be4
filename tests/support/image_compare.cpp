#include "msm/test/image_compare.h"
#include "msm/image/io.h"

#include <fmt/core.h>

namespace msm::image {

namespace {
void check(std::string& violations, const char* name, double value, double limit) {
  if (!(value <= limit)) violations += fmt::format("  {} = {:.6g} > tolerance {:.6g}\n", name, value, limit);
}
} // namespace

CompareResult compare(const Image& actual, const Image& reference, const Tolerances& tol,
                      const CompareOptions& options) {
  CompareResult result;
  std::string violations;
  bool comparable = true;
  try {
    result.metrics = compute_metrics(actual, reference, options.metrics);
    const Metrics& m = result.metrics;
    check(violations, "mae", m.mae, tol.max_mae);
    check(violations, "rmse", m.rmse, tol.max_rmse);
    check(violations, "max_error", m.max_error, tol.max_error);
    check(violations, "share_above_1pct", m.share_above_1pct, tol.max_share_above_1pct);
    check(violations, "share_above_3pct", m.share_above_3pct, tol.max_share_above_3pct);
    check(violations, "share_above_10pct", m.share_above_10pct, tol.max_share_above_10pct);
    check(violations, "light_leaking", m.light_leaking, tol.max_light_leaking);
    check(violations, "over_darkening", m.over_darkening, tol.max_over_darkening);
    if (m.non_finite > tol.max_non_finite)
      violations += fmt::format("  non_finite = {} > tolerance {}\n", m.non_finite, tol.max_non_finite);
  } catch (const std::exception& e) {
    comparable = false;
    violations += fmt::format("  cannot compare: {}\n", e.what());
  }
  result.passed = violations.empty();
  result.report = fmt::format("{} ({}x{} vs reference {}x{})\n", result.passed ? "PASS" : "FAIL", actual.width(),
                              actual.height(), reference.width(), reference.height());
  if (comparable) result.report += format_metrics(result.metrics);
  if (!result.passed) result.report += "violations:\n" + violations;
  if (result.passed || options.failure_dir.empty()) return result;

  const auto& dir = options.failure_dir;
  std::string written;
  auto attempt = [&](const std::filesystem::path& file, auto&& write) {
    try {
      write(dir / file);
      written += " " + file.string();
    } catch (const std::exception& e) {
      result.report += fmt::format("could not write {}: {}\n", (dir / file).string(), e.what());
    }
  };
  try {
    std::filesystem::create_directories(dir);
  } catch (const std::exception& e) {
    result.report += fmt::format("could not create {}: {}\n", dir.string(), e.what());
    return result;
  }
  if (!actual.empty()) {
    attempt("actual.exr", [&](const auto& p) { write_exr(p, actual); });
    attempt("actual.png", [&](const auto& p) { write_png(p, select_signal(actual, options.metrics.channel)); });
  }
  if (!reference.empty()) {
    attempt("reference.exr", [&](const auto& p) { write_exr(p, reference); });
    attempt("reference.png", [&](const auto& p) { write_png(p, select_signal(reference, options.metrics.channel)); });
  }
  if (comparable)
    attempt("error.png",
            [&](const auto& p) { write_error_png(p, actual, reference, options.error_range, options.metrics); });
  result.report += fmt::format("images written to {}:{}\n", dir.string(), written);
  return result;
}

} // namespace msm::image
