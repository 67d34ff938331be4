// One name for one thing across msm's subcommands: the options that several commands share (a
// technique list, the output directory, the scene, the device, a probe's light count...), each
// declared once with its meaning and the other names people reach for. Commands register them
// through add_term, which gives the same name and the same opening words of help everywhere; the
// render settings' names come from msm/render/settings_schema.h. msm_cli_settings_test walks every
// command's options and refuses a synonym where the term's own name belongs.
#pragma once
#include <CLI/CLI.hpp>

#include <span>
#include <string>
#include <string_view>

namespace msm::tool {

struct Term {
  std::string_view name;                   // the long option, "--out"
  std::string_view short_name;             // "-o", or empty
  std::string_view meaning;                // the help's opening words, the same in every command
  std::span<const std::string_view> other; // names that would mean the same: never an option's name
};

std::span<const Term> vocabulary();
// The term of that long name (std::invalid_argument if there is none).
const Term& term(std::string_view name);

// "-o,--out"
std::string option_names(const Term& term);

// The term's option on a command: its names, and its meaning followed by what the command adds.
template <typename T>
CLI::Option* add_term(CLI::App* cmd, std::string_view name, T& target, std::string detail = {}) {
  const Term& t = term(name);
  return cmd->add_option(option_names(t), target, std::string(t.meaning) + detail);
}
CLI::Option* add_term_flag(CLI::App* cmd, std::string_view name, bool& target, std::string detail = {});

} // namespace msm::tool
