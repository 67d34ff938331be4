#include "usage.h"

#include "msm/util/spelling.h"

#include <fmt/core.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace msm::tool {

const char* exit_status_help() {
  return "Exit status:\n"
         "  0    success (also --help, --version and msm help)\n"
         "  1    the command line was not understood: an unknown command or option, a missing or malformed "
         "value (the message names it)\n"
         "  2    the command failed: a bad value or input file, no Vulkan device, output not writable (nothing "
         "is left half written)\n"
         "  3    evaluate --stop-after only (a test hook that stops as a kill would)\n"
         "  128+n  killed by signal n";
}

namespace {

std::string suggestion(const std::vector<std::string>& near, const std::string& prefix) {
  if (near.empty()) return "";
  std::string s = " (did you mean " + prefix + near[0];
  for (size_t i = 1; i < near.size(); ++i) s += (i + 1 == near.size() ? " or " : ", ") + prefix + near[i];
  return s + "?)";
}

// What the parser left unmatched in one (sub)command, each with the nearest valid name: options
// against the command's long option names, a word against its subcommands' names. A word just
// after an unknown option is taken as that option's value and not reported again.
std::vector<std::string> unknown_items(const CLI::App& app) {
  std::vector<std::string> lines;
  bool after_option = false;
  for (const std::string& item : app.remaining(false)) {
    if (item.size() > 1 && item[0] == '-') {
      std::string name = item.substr(item.find_first_not_of('-'));
      name = name.substr(0, name.find('='));
      std::vector<std::string> names;
      for (const CLI::Option* o : app.get_options())
        for (const std::string& l : o->get_lnames()) names.push_back(l);
      lines.push_back(fmt::format("unknown option '{}'{}", item, suggestion(util::nearest_names(name, names), "--")));
      after_option = true;
      continue;
    }
    if (!app.get_subcommands({}).empty()) {
      std::vector<std::string> names;
      for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
      lines.push_back(fmt::format("unknown command '{}'{}", item, suggestion(util::nearest_names(item, names), "")));
      break; // what follows belonged to that command
    }
    if (!after_option) lines.push_back(fmt::format("unexpected argument '{}'", item));
    after_option = false;
  }
  return lines;
}

} // namespace

void add_help(CLI::App& app) {
  auto command = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("help", "Print the help of msm, or of one command (msm help render)");
  cmd->add_option("COMMAND", *command, "The command");
  cmd->callback([&app, command] {
    if (command->empty()) {
      // Not app.help(): with `help` parsed, it would print the help of `help`.
      fmt::print("{}", app.get_formatter()->make_help(&app, app.get_name(), CLI::AppFormatMode::Normal));
      return;
    }
    std::vector<std::string> names;
    for (CLI::App* sub : app.get_subcommands({})) {
      if (sub->get_name() == *command) {
        fmt::print("{}", sub->help(app.get_name()));
        return;
      }
      names.push_back(sub->get_name());
    }
    throw CLI::ValidationError(
        fmt::format("unknown command '{}'{}", *command, suggestion(util::nearest_names(*command, names), "")));
  });
}

int report_parse_error(CLI::App& app, const CLI::ParseError& error) {
  if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error); // help, version
  // The subcommand that rejected it: the innermost one the parser had entered.
  std::string command = "msm";
  std::vector<std::string> unknown = unknown_items(app);
  for (const CLI::App* sub = &app; !sub->get_subcommands().empty();) {
    sub = sub->get_subcommands().front();
    command += " " + sub->get_name();
    std::vector<std::string> more = unknown_items(*sub);
    unknown.insert(unknown.end(), more.begin(), more.end());
  }
  for (const std::string& line : unknown) fmt::print(stderr, "{}: error: {}\n", command, line);
  // The parser's own message, unless it only restates the unknown items ("not expected") or
  // follows from a mistyped command ("a subcommand is required").
  bool no_command = dynamic_cast<const CLI::RequiredError*>(&error) != nullptr && app.get_subcommands().empty();
  bool restated = dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr || no_command;
  if (unknown.empty() && no_command)
    fmt::print(stderr, "msm: error: no command given ('msm help' lists them)\n");
  else if (unknown.empty() || !restated)
    fmt::print(stderr, "{}: error: {}\n", command, error.what());
  fmt::print(stderr, "Run '{} --help' for the usage.\n", command);
  return kExitUsage;
}

} // namespace msm::tool
