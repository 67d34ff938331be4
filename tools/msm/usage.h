// msm's exit statuses and how a command line the parser rejects is reported: one documented set
// (README.md, the footer of `msm --help`) instead of CLI11's own codes (104 to 114).
#pragma once
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>

namespace msm::tool {

constexpr int kExitUsage = 1;   // the command line was not understood (parser: unknown, missing, malformed)
constexpr int kExitFailure = 2; // the command ran and failed: bad value or file, no device, cannot write

// The footer of `msm --help`: the exit statuses.
const char* exit_status_help();

// `msm help [COMMAND]`: the help of msm or of one command (stdout, exit 0); an unknown command is
// a usage error naming the nearest.
void add_help(CLI::App& app);

// Prints why the parser rejected the command line (naming the subcommand) and returns the exit
// status: 0 for --help and --version (CLI11 signals them as errors too), else kExitUsage.
int report_parse_error(CLI::App& app, const CLI::ParseError& error);

// An older spelling of an option, read for one version: hidden from the help, it sets the same
// value and warns once on stderr, naming the current one.
template <typename T>
CLI::Option* add_deprecated_option(CLI::App* cmd, const std::string& old_name, const std::string& current, T& target) {
  auto warned = std::make_shared<bool>(false);
  return cmd->add_option(old_name, target, "")->group("")->each([warned, old_name, current](const std::string&) {
    if (*warned) return;
    *warned = true;
    std::fprintf(stderr, "msm: warning: %s is deprecated and goes in the next version: use %s\n", old_name.c_str(),
                 current.c_str());
  });
}

// The same for a flag.
inline CLI::Option* add_deprecated_flag(CLI::App* cmd, const std::string& old_name, const std::string& current,
                                        bool& target) {
  return cmd->add_flag(old_name, target, "")->group("")->each([old_name, current](const std::string&) {
    std::fprintf(stderr, "msm: warning: %s is deprecated and goes in the next version: use %s\n", old_name.c_str(),
                 current.c_str());
  });
}

} // namespace msm::tool
