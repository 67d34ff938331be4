#include "msm/settings_declaration.h"

#include "msm/util/spelling.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace msm {
namespace {

using json = nlohmann::json;

std::string names_text(std::span<const std::string_view> names) {
  std::string text;
  for (size_t i = 0; i < names.size(); ++i)
    text += fmt::format("{}{}", i == 0 ? "" : i + 1 == names.size() ? " or " : ", ", names[i]);
  return text;
}

} // namespace

void throw_unknown_setting(std::string_view key, const std::vector<std::string>& keys) {
  throw SettingError(fmt::format("unknown setting{}", util::did_you_mean(key, keys)));
}

std::string setting_range_text(const SettingRule& s) {
  switch (s.type) {
  case SettingType::number: return fmt::format("[{}, {}]", float(s.min), float(s.max)); // as the float reads
  case SettingType::integer:
    return s.choices.empty() ? fmt::format("[{}, {}]", std::int64_t(s.min), std::int64_t(s.max))
                             : names_text(s.choices);
  case SettingType::flag: return "true or false";
  case SettingType::choice: return names_text(s.choices);
  case SettingType::technique: return "a technique (msm techniques)";
  case SettingType::parameters: return "{\"NAME\": value, ...}";
  }
  return "";
}

std::pair<double, double> setting_control_range(const SettingRule& s) {
  if (s.control_min == 0 && s.control_max == 0) return {s.min, s.max};
  return {s.control_min, s.control_max};
}

void check_setting(const SettingRule& s, const json& v) {
  if (s.nullable && v.is_null()) return;
  auto expected = [&](std::string_view what) {
    throw SettingError(fmt::format("expected {}, got {}", what, v.dump()));
  };
  switch (s.type) {
  case SettingType::number:
    if (!v.is_number()) expected("a number");
    if (!std::isfinite(v.get<double>())) throw SettingError(fmt::format("{} is not a finite number", v.get<double>()));
    break;
  case SettingType::integer:
    if (!v.is_number_integer()) expected("an integer");
    break;
  case SettingType::flag:
    if (!v.is_boolean()) expected("true or false");
    break;
  case SettingType::choice:
  case SettingType::technique:
    if (!v.is_string()) expected("a string");
    break;
  case SettingType::parameters:
    if (!v.is_null() && !v.is_object()) expected("{\"NAME\": value, ...} or null");
    if (v.is_object())
      for (const auto& [name, value] : v.items())
        if (!value.is_string() && !value.is_boolean() && !value.is_number())
          throw SettingError(fmt::format("expected a number, true/false or a name, got {}", value.dump()), "/" + name);
    break;
  }
  if (s.type == SettingType::integer && !s.choices.empty() &&
      std::find(s.choices.begin(), s.choices.end(), v.dump()) == s.choices.end())
    throw SettingError(fmt::format("{}: expected {}", v.dump(), names_text(s.choices)));
  // A number may be kept as a float: the range is compared as the float reads (1e-6 is
  // 9.99999997e-07 as a float, inside [1e-6, 1e6]).
  if (s.type == SettingType::number &&
      !(float(v.get<double>()) >= float(s.min) && float(v.get<double>()) <= float(s.max)))
    throw SettingError(fmt::format("{} is outside {}", float(v.get<double>()), setting_range_text(s)));
  if (s.type == SettingType::integer && !(v.get<double>() >= s.min && v.get<double>() <= s.max))
    throw SettingError(fmt::format("{} is outside {}", v.dump(), setting_range_text(s)));
  if (s.type == SettingType::choice) {
    const std::string name = v.get<std::string>();
    if (std::find(s.choices.begin(), s.choices.end(), name) == s.choices.end()) {
      const std::vector<std::string> choices(s.choices.begin(), s.choices.end());
      throw SettingError(
          fmt::format("'{}': expected {}{}", name, names_text(s.choices), util::did_you_mean(name, choices)));
    }
  }
  if (s.check) s.check(v);
}

std::string setting_option_name(const SettingRule& s, bool flag_default) {
  std::string name(s.key);
  std::replace(name.begin(), name.end(), '_', '-');
  if (s.type == SettingType::flag && flag_default) return "--no-" + name;
  return "--" + name;
}

json setting_from_text(const SettingRule& s, std::string_view text) {
  const std::string t(text);
  char* end = nullptr;
  errno = 0;
  switch (s.type) {
  case SettingType::number: {
    const double v = std::strtod(t.c_str(), &end);
    if (t.empty() || *end != '\0') throw SettingError(fmt::format("expected a number, got '{}'", t));
    if (!std::isfinite(v)) throw SettingError(fmt::format("{} is not a finite number", t));
    return v;
  }
  case SettingType::integer: {
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (t.empty() || *end != '\0' || errno == ERANGE)
      throw SettingError(fmt::format("expected an integer, got '{}'", t));
    return std::int64_t(v);
  }
  case SettingType::flag:
    if (t == "true" || t == "on" || t == "1") return true;
    if (t == "false" || t == "off" || t == "0") return false;
    throw SettingError(fmt::format("expected true or false, got '{}'", t));
  case SettingType::choice:
  case SettingType::technique: return t;
  case SettingType::parameters: break;
  }
  throw SettingError("set each parameter by name: NAME=VALUE");
}

} // namespace msm
