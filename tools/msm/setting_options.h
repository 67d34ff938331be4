// The command-line options of a table of declared settings (msm/settings_declaration.h): msm
// render's (msm/render/settings_schema.h) and msm reference's (msm/reference/settings_schema.h)
// options are made here from their tables, one per setting: --KEY-WITH-DASHES, a flag that is on
// by default as --no-KEY, its help the declaration's meaning and range, its default the settings
// struct's.
#pragma once

#include "commands.h"
#include "msm/settings_declaration.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>

namespace msm::tool {

// The text of each setting given on the command line, by key (empty: not given).
using GivenSettings = std::map<std::string, std::optional<std::string>, std::less<>>;

// One setting's option, its text kept in `text`; a value that is not of the setting's type is a
// parse error naming the option. `fallback`: the setting's default, as JSON.
CLI::Option* add_setting_option(CLI::App* cmd, const SettingRule& setting, const nlohmann::json& fallback,
                                std::optional<std::string>& text);
// Why a setting's value from the command line is refused, naming the option
// ("width = 0 is outside [1, 16384] (--width)", "--lookup bilinar: use auto, ... (did you mean bilinear?)").
std::string setting_problem(const SettingRule& setting, const std::string& option, const std::string& text,
                            const SettingError& error);

// An option for each setting of the table (a technique and its parameters have their own: -t,
// --set), the help showing each one's default from `defaults`.
template <class Settings>
void add_setting_options(CLI::App* cmd, std::span<const BasicSettingDeclaration<Settings>> table,
                         const Settings& defaults, GivenSettings& given) {
  for (const auto& setting : table)
    if (setting.type != SettingType::technique && setting.type != SettingType::parameters)
      add_setting_option(cmd, setting.rule(), setting.get(defaults), given[std::string(setting.key)]);
}

// The given texts, each checked against its declaration and set; UsageError naming the option.
template <class Settings>
void apply_given_settings(std::span<const BasicSettingDeclaration<Settings>> table, const GivenSettings& given,
                          Settings& settings) {
  for (const auto& [key, text] : given) {
    if (!text) continue;
    const auto& setting = find_setting(table, key);
    const std::string option = setting_option_name(setting, Settings{});
    try {
      apply_setting(settings, setting, setting_from_text(setting, *text));
    } catch (const SettingError& e) { throw UsageError(setting_problem(setting.rule(), option, *text, e)); }
  }
}

// A check of an integer option's range whose failure is a bad value, exit status 2 (UsageError:
// "--frame 10000 is outside [0, 9999]"), as a declared setting's range is; CLI::Range would make it
// a command line the parser did not understand (status 1). Text that is not an integer is left to
// the parser.
CLI::Validator integer_range(const std::string& option, long long min, long long max);

} // namespace msm::tool
