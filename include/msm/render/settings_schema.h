// The render settings, each declared once: its key, type, range or choices, default and meaning,
// and how it reads and writes RenderSettings. The command line's options (--key-with-dashes), the
// JSON outputs (render.json, bench), view files and viewer scripts (`set KEY VALUE`) and the
// viewer's panel are all made from this table, so they use the same names and the same checks.
#pragma once

#include "msm/render/renderer.h"

#include <nlohmann/json.hpp>

#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace msm::render {

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
  number,     // a finite float in [min, max]
  integer,    // an int in [min, max]
  flag,       // true or false
  choice,     // one of `choices`, by name
  technique,  // a technique's name or alias (msm techniques)
  parameters, // the technique's parameters by name ({"NAME": value}; msm techniques NAME)
};

struct SettingDeclaration {
  std::string_view key;                        // JSON and view-file key; the command line's option is --key-with-dashes
  SettingType type;                            //
  std::string_view help;                       // one line: what it means, and what its default means where it depends
  double min = 0, max = 0;                     // number, integer: the valid range, ends included
  std::span<const std::string_view> choices{}; // choice: the names, as written
  bool nullable = false;                       // null: the default that depends (the technique's, the scene's)
  nlohmann::json (*get)(const RenderSettings&);        // the value as JSON (null where nullable and unset)
  void (*set)(RenderSettings&, const nlohmann::json&); // from a value that check_setting accepted
};

// Every setting, in the order of the JSON outputs and view files (the technique first: the
// parameters are its own).
std::span<const SettingDeclaration> setting_declarations();
// The declaration of a key; SettingError "unknown setting (did you mean ...?)" otherwise.
const SettingDeclaration& find_setting(std::string_view key);
std::vector<std::string> setting_keys();

// SettingError unless `value` has the declaration's type and lies in its range or choices.
void check_setting(const SettingDeclaration& setting, const nlohmann::json& value);
// check_setting, then sets it.
void apply_setting(RenderSettings& settings, const SettingDeclaration& setting, const nlohmann::json& value);
// Every setting under its key (the technique's parameters by name).
nlohmann::json settings_json(const RenderSettings& settings);

// The command line's name of a setting (--filter-size) and the text of a value as it is typed
// there (a number, a name; a flag has none). A flag whose default is on is given as --no-key.
std::string setting_option_name(const SettingDeclaration& setting, const RenderSettings& defaults = {});
// The value of a setting from command-line text: SettingError "expected ..." where the text is not
// of the setting's type (the range is check_setting's).
nlohmann::json setting_from_text(const SettingDeclaration& setting, std::string_view text);
// "[1, 16384]", "auto, bilinear, nearest or dither", "true or false".
std::string setting_range_text(const SettingDeclaration& setting);

} // namespace msm::render
