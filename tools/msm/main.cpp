// msm: the command-line front end of the moment shadow mapping toolkit.
#include "commands.h"
#include "usage.h"

#include "msm/util/limits.h"
#include "msm/version.h"

#include <fmt/core.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

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

// CLI11 reports an option of one value given twice as "--width: At Most 1 required but received 3"
// (counting its values and separators): said plainly, naming the option.
CLI::ArgumentMismatch plain_argument_mismatch(const CLI::ArgumentMismatch& error) {
  const std::string what = error.what();
  const std::string at_most = ": At Most 1 required but received ";
  const std::size_t at = what.find(at_most);
  if (at == std::string::npos) return error;
  return CLI::ArgumentMismatch(fmt::format("{} given more than once: it takes one value", what.substr(0, at)));
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"msm: moment shadow mapping toolkit (filtered, soft and translucent shadows, measured against "
               "ray-traced ground truth)"};
  app.set_version_flag("--version",
                       fmt::format("msm {}.{}.{}", MSM_VERSION_MAJOR, MSM_VERSION_MINOR, MSM_VERSION_PATCH));
  app.require_subcommand(1);
  app.footer(msm::tool::exit_status_help()); // before the subcommands: each inherits it
  msm::tool::add_kernels(app);
  msm::tool::add_techniques(app);
  msm::tool::add_reconstruct(app);
  msm::tool::add_compare(app);
#if MSM_TOOL_RENDER
  msm::tool::add_demo(app);
  msm::tool::add_bench(app);
  msm::tool::add_render(app);
  msm::tool::add_report(app);
  msm::tool::add_scenes(app);
  msm::tool::add_view(app);
#endif
  msm::tool::add_lights(app);
  msm::tool::add_reference(app);
  msm::tool::add_evaluate(app);
  msm::tool::add_help(app);
  refuse_non_finite_numbers(app);
  try {
    msm::limits::check_environment(); // a mistyped override is refused before any work
    app.parse(argc, argv);
  } catch (const CLI::ArgumentMismatch& e) {
    return msm::tool::report_parse_error(app, plain_argument_mismatch(e));
  } catch (const CLI::ParseError& e) { return msm::tool::report_parse_error(app, e); } catch (const std::exception& e) {
    fmt::print(stderr, "msm: error: {}\n", e.what());
    return msm::tool::kExitFailure;
  }
  return 0;
}
