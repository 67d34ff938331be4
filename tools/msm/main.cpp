// msm: the command-line front end of the moment shadow mapping toolkit.
#include "commands.h"
#include "usage.h"

#include "msm/version.h"

#include <fmt/core.h>

#include <cstdio>
#include <exception>

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
  msm::tool::add_scenes(app);
  msm::tool::add_view(app);
#endif
  msm::tool::add_lights(app);
  msm::tool::add_reference(app);
  msm::tool::add_evaluate(app);
  msm::tool::add_help(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) { return msm::tool::report_parse_error(app, e); } catch (const std::exception& e) {
    fmt::print(stderr, "msm: error: {}\n", e.what());
    return msm::tool::kExitFailure;
  }
  return 0;
}
