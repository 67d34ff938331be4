// Subcommands of the msm tool. Each registers itself on the CLI11 app and runs from its callback.
#pragma once
#include <CLI/CLI.hpp>

namespace msm::tool {

// The whole msm command line: every subcommand below and `help`, each with its options; every
// floating-point option refuses non-finite numbers.
void build_app(CLI::App& app);

void add_demo(CLI::App& app);
void add_evaluate(CLI::App& app);
void add_kernels(CLI::App& app);
void add_bench(CLI::App& app);
void add_techniques(CLI::App& app);
void add_reconstruct(CLI::App& app);
void add_compare(CLI::App& app);
void add_lights(CLI::App& app); // msm lights, and msm probe: its alias of the first release
void add_reference(CLI::App& app);
void add_render(CLI::App& app);
void add_report(CLI::App& app);
void add_scenes(CLI::App& app);
void add_view(CLI::App& app);

// Thrown by commands for bad input: main prints the message and exits with status 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

} // namespace msm::tool
