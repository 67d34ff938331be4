#include "setting_options.h"

#include "msm/util/spelling.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <vector>

namespace msm::tool {
namespace {

// The help line of a setting's option: its meaning and range.
std::string setting_help(const SettingRule& setting, bool negated) {
  if (negated) return fmt::format("Turn off (on by default): {}", setting.help);
  if (setting.type == SettingType::number || (setting.type == SettingType::integer && setting.choices.empty()))
    return fmt::format("{}; in {}", setting.help, setting_range_text(setting));
  return std::string(setting.help);
}

std::string default_text(const nlohmann::json& value) {
  if (value.is_null()) return "";
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) return fmt::format("{}", value.get<float>());
  return value.dump();
}

} // namespace

CLI::Option* add_setting_option(CLI::App* cmd, const SettingRule& setting, const nlohmann::json& fallback,
                                std::optional<std::string>& text) {
  if (setting.type == SettingType::flag) {
    const bool value = !fallback.get<bool>();
    return cmd->add_flag_callback(
        setting_option_name(setting, !value), [&text, value] { text = value ? "true" : "false"; },
        setting_help(setting, !value));
  }
  CLI::Option* option = cmd->add_option(setting_option_name(setting), text, setting_help(setting, false));
  option->type_name(setting.type == SettingType::number    ? "FLOAT"
                    : setting.type == SettingType::integer ? "INT"
                                                           : "TEXT");
  option->default_str(setting.nullable ? "" : default_text(fallback));
  option->check([setting](const std::string& value) -> std::string {
    try {
      setting_from_text(setting, value);
    } catch (const SettingError& e) { return e.what(); }
    return {};
  });
  return option;
}

std::string setting_problem(const SettingRule& setting, const std::string& option, const std::string& text,
                            const SettingError& error) {
  if (setting.type == SettingType::choice) {
    const std::vector<std::string> choices(setting.choices.begin(), setting.choices.end());
    return fmt::format("{} {}: use {}{}", option, text, setting_range_text(setting), util::did_you_mean(text, choices));
  }
  if (setting.type == SettingType::integer && !setting.choices.empty())
    return fmt::format("{} {}: use {}", option, text, setting_range_text(setting));
  if (setting.type == SettingType::number || setting.type == SettingType::integer) {
    std::string label(setting.key);
    std::replace(label.begin(), label.end(), '_', ' ');
    return fmt::format("{} = {} is outside {} ({})", label, text, setting_range_text(setting), option);
  }
  return fmt::format("{} {}: {}", option, text, error.what());
}

CLI::Validator integer_range(const std::string& option, long long min, long long max) {
  return CLI::Validator(
      [option, min, max](std::string& text) -> std::string {
        char* end = nullptr;
        errno = 0;
        const long long v = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || *end != '\0') return {}; // malformed: the parser's
        if (errno == ERANGE || v < min || v > max)
          throw UsageError(fmt::format("{} {} is outside [{}, {}]", option, text, min, max));
        return {};
      },
      fmt::format("INT in [{} - {}]", min, max));
}

} // namespace msm::tool
