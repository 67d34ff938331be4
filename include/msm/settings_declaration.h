// A setting declared once: its key, type, range or choices, default (the settings struct's) and
// meaning, and how it reads and writes its settings struct. The tables of the renderer's settings
// (msm/render/settings_schema.h) and the ray tracer's (msm/reference/settings_schema.h) are made of
// these, and the command lines, JSON outputs, view files and the viewer's panel are made from the
// tables: the same names and the same checks everywhere.
#pragma once

#include <nlohmann/json.hpp>

#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace msm {

// A value of the wrong type, outside its range or not one of the choices: the message says what
// is expected ("expected an integer, got 2.5", "0 is outside [1, 16384]").
// `pointer`: where inside the value, as a JSON pointer ("/beta" of the parameters), or empty.
class SettingError : public std::runtime_error {
 public:
  explicit SettingError(const std::string& what, std::string pointer = {})
      : std::runtime_error(what), pointer(std::move(pointer)) {}
  std::string pointer;
};

enum class SettingType {
  number,     // a finite number in [min, max]
  integer,    // an integer in [min, max], and one of `choices` (as written) where it has them
  flag,       // true or false
  choice,     // one of `choices`, by name
  technique,  // a technique's name or alias (msm techniques); `check` knows them
  parameters, // the technique's parameters by name ({"NAME": value}; msm techniques NAME)
};

// How a control shows a number where a plain slider over [min, max] does not suit it.
enum class SettingScale {
  linear,      // a slider over [min, max]
  logarithmic, // a slider over [min, max], logarithmic (ranges of several decades)
};

// What every declaration has, whatever settings struct it belongs to.
struct SettingRule {
  std::string_view key;                        // JSON and view-file key; the command line's option is --key-with-dashes
  SettingType type;                            //
  std::string_view help;                       // one line: what it means, and what its default means where it depends
  double min = 0, max = 0;                     // number, integer: the valid range, ends included
  std::span<const std::string_view> choices{}; // choice: the names, as written; integer: its only values, if any
  bool nullable = false;                       // null: the default that depends (the technique's, the scene's)
  // number, integer: the range a control offers ([min, max] where both are 0), its scale, and for
  // an integer the step between its values from control_min (0: 1)
  double control_min = 0, control_max = 0;
  SettingScale scale = SettingScale::linear;
  int control_step = 0;
  void (*check)(const nlohmann::json&) = nullptr; // more than the type can say (a technique's name); SettingError
};

// A declaration of a member of `Settings`: the rule, and its accessors.
template <class Settings>
struct BasicSettingDeclaration {
  std::string_view key;
  SettingType type;
  std::string_view help;
  double min = 0, max = 0;
  std::span<const std::string_view> choices{};
  bool nullable = false;
  double control_min = 0, control_max = 0;
  SettingScale scale = SettingScale::linear;
  int control_step = 0;
  void (*check)(const nlohmann::json&) = nullptr;
  nlohmann::json (*get)(const Settings&);        // the value as JSON (null where nullable and unset)
  void (*set)(Settings&, const nlohmann::json&); // from a value that check_setting accepted

  SettingRule rule() const {
    return {key, type, help, min, max, choices, nullable, control_min, control_max, scale, control_step, check};
  }
};

// SettingError unless `value` has the rule's type and lies in its range or choices.
void check_setting(const SettingRule& rule, const nlohmann::json& value);
// The value of a setting from command-line text: SettingError "expected ..." where the text is not
// of the setting's type (the range is check_setting's).
nlohmann::json setting_from_text(const SettingRule& rule, std::string_view text);
// "[1, 16384]", "auto, bilinear, nearest or dither", "true or false".
std::string setting_range_text(const SettingRule& rule);
// The command line's name of a setting (--filter-size); a flag whose default is on is --no-KEY.
std::string setting_option_name(const SettingRule& rule, bool flag_default = false);
// The range a control offers: [control_min, control_max] where declared, else [min, max].
std::pair<double, double> setting_control_range(const SettingRule& rule);
// SettingError "unknown setting (did you mean ...?)".
[[noreturn]] void throw_unknown_setting(std::string_view key, const std::vector<std::string>& keys);

template <class Settings>
void check_setting(const BasicSettingDeclaration<Settings>& setting, const nlohmann::json& value) {
  check_setting(setting.rule(), value);
}
template <class Settings>
nlohmann::json setting_from_text(const BasicSettingDeclaration<Settings>& setting, std::string_view text) {
  return setting_from_text(setting.rule(), text);
}
template <class Settings>
std::string setting_range_text(const BasicSettingDeclaration<Settings>& setting) {
  return setting_range_text(setting.rule());
}
template <class Settings>
std::pair<double, double> setting_control_range(const BasicSettingDeclaration<Settings>& setting) {
  return setting_control_range(setting.rule());
}
template <class Settings>
std::string setting_option_name(const BasicSettingDeclaration<Settings>& setting, const Settings& defaults = {}) {
  return setting_option_name(setting.rule(),
                             setting.type == SettingType::flag && setting.get(defaults).template get<bool>());
}
// check_setting, then sets it.
template <class Settings>
void apply_setting(Settings& settings, const BasicSettingDeclaration<Settings>& setting, const nlohmann::json& value) {
  check_setting(setting, value);
  setting.set(settings, value);
}

template <class Settings>
std::vector<std::string> setting_keys(std::span<const BasicSettingDeclaration<Settings>> table) {
  std::vector<std::string> keys;
  for (const auto& s : table) keys.emplace_back(s.key);
  return keys;
}
// The declaration of a key; SettingError "unknown setting (did you mean ...?)" otherwise.
template <class Settings>
const BasicSettingDeclaration<Settings>& find_setting(std::span<const BasicSettingDeclaration<Settings>> table,
                                                      std::string_view key) {
  for (const auto& s : table)
    if (s.key == key) return s;
  throw_unknown_setting(key, setting_keys(table));
}
// Every setting under its key, in the table's order.
template <class Settings>
nlohmann::json settings_json(std::span<const BasicSettingDeclaration<Settings>> table, const Settings& settings) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& s : table) out[std::string(s.key)] = s.get(settings);
  return out;
}
// The inverse: each key of `object` checked and set; SettingError with the key's JSON pointer
// ("/filter_sise: unknown setting (did you mean filter_size?)").
template <class Settings>
void apply_settings_json(std::span<const BasicSettingDeclaration<Settings>> table, Settings& settings,
                         const nlohmann::json& object) {
  if (!object.is_object()) throw SettingError("expected {\"KEY\": value, ...}, got " + object.dump());
  for (const auto& [key, value] : object.items()) try {
      apply_setting(settings, find_setting(table, key), value);
    } catch (const SettingError& e) { throw SettingError(e.what(), "/" + key + e.pointer); }
}

} // namespace msm
