#include "usage.h"

#include <fmt/core.h>

#include <cstdio>
#include <string>

namespace msm::tool {

const char* exit_status_help() {
  return "Exit status:\n"
         "  0    success (also --help and --version)\n"
         "  1    the command line was not understood: an unknown command or option, a missing or malformed "
         "value (the message names it)\n"
         "  2    the command failed: a bad value or input file, no Vulkan device, output not writable (nothing "
         "is left half written)\n"
         "  3    evaluate --stop-after only (a test hook that stops as a kill would)\n"
         "  128+n  killed by signal n";
}

int report_parse_error(CLI::App& app, const CLI::ParseError& error) {
  if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error); // help, version
  // The subcommand that rejected it: the innermost one the parser had entered.
  std::string command = "msm";
  for (const CLI::App* sub = &app; !sub->get_subcommands().empty();) {
    sub = sub->get_subcommands().front();
    command += " " + sub->get_name();
  }
  fmt::print(stderr, "{}: error: {}\nRun '{} --help' for the usage.\n", command, error.what(), command);
  return kExitUsage;
}

} // namespace msm::tool
