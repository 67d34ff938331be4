// The msm command line: every subcommand and its options on one CLI11 app.
#include "commands.h"
#include "usage.h"

#include "msm/version.h"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>
#include <string>

namespace msm::tool {
namespace {

// Every number that enters through the command line is finite: "nan" and "inf" parse as floats,
// and a NaN passes every range check written as `value < min || value > max`. One check on every
// floating-point option of every command (lists are checked value by value), so that no option
// can forget it.
void refuse_non_finite_numbers(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_name().find("FLOAT") == std::string::npos) continue;
    option->check([](const std::string& value) -> std::string {
      char* end = nullptr;
      const double v = std::strtod(value.c_str(), &end);
      if (end != value.c_str() && *end == '\0' && !std::isfinite(v))
        return fmt::format("{} is not a finite number", value);
      return {};
    });
  }
  for (CLI::App* sub : app.get_subcommands({})) refuse_non_finite_numbers(*sub);
}

} // namespace

void build_app(CLI::App& app) {
  app.description("msm: moment shadow mapping toolkit (filtered, soft and translucent shadows, measured against "
                  "ray-traced ground truth)");
  app.set_version_flag("--version",
                       fmt::format("msm {}.{}.{}", MSM_VERSION_MAJOR, MSM_VERSION_MINOR, MSM_VERSION_PATCH));
  app.require_subcommand(1);
  app.footer(exit_status_help()); // before the subcommands: each inherits it
  add_kernels(app);
  add_techniques(app);
  add_reconstruct(app);
  add_compare(app);
#if MSM_TOOL_RENDER
  add_demo(app);
  add_bench(app);
  add_render(app);
  add_report(app);
  add_scenes(app);
  add_view(app);
#endif
  add_lights(app);
  add_reference(app);
  add_evaluate(app);
  add_help(app);
  refuse_non_finite_numbers(app);
}

} // namespace msm::tool
