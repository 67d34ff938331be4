// The ray tracer's settings (msm::reference::Settings), each declared once, as the renderer's are
// (msm/render/settings_schema.h): key, type, range or choices, default and meaning, and how it
// reads and writes Settings. msm reference's options (--key-with-dashes) and reference.json are
// made from this table; a setting both have uses msm render's key (width, shadow_size,
// filter_sigma, light_extent_deg, ...).
#pragma once

#include "msm/reference/reference.h"
#include "msm/settings_declaration.h"

#include <nlohmann/json.hpp>

#include <span>
#include <string_view>

namespace msm::reference {

using SettingDeclaration = msm::BasicSettingDeclaration<Settings>;

// Every setting, in the order of reference.json.
std::span<const SettingDeclaration> setting_declarations();
// The declaration of a key; SettingError "unknown setting (did you mean ...?)" otherwise.
const SettingDeclaration& find_setting(std::string_view key);
// Every setting under its key, in the table's order (null: an override not given).
nlohmann::ordered_json settings_json(const Settings& settings);
// The inverse: each key of `object` checked and set; SettingError with the key's JSON pointer.
void apply_settings_json(Settings& settings, const nlohmann::json& object);

} // namespace msm::reference
