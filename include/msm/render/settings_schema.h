// The render settings, each declared once: its key, type, range or choices, default and meaning,
// and how it reads and writes RenderSettings. The command line's options (--key-with-dashes), the
// JSON outputs (render.json, bench), view files and viewer scripts (`set KEY VALUE`) and the
// viewer's panel are all made from this table, so they use the same names and the same checks.
#pragma once

#include "msm/render/renderer.h"
#include "msm/settings_declaration.h"

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace msm::render {

using msm::SettingError;
using msm::SettingScale;
using msm::SettingType;
using SettingDeclaration = msm::BasicSettingDeclaration<RenderSettings>;

// Every setting, in the order of the JSON outputs and view files (the technique first: the
// parameters are its own).
std::span<const SettingDeclaration> setting_declarations();
// The declaration of a key; SettingError "unknown setting (did you mean ...?)" otherwise.
const SettingDeclaration& find_setting(std::string_view key);
std::vector<std::string> setting_keys();

// Every setting under its key (the technique's parameters by name).
nlohmann::json settings_json(const RenderSettings& settings);
// What each declaration gives (msm/settings_declaration.h).
using msm::apply_setting;
using msm::check_setting;
using msm::setting_control_range;
using msm::setting_from_text;
using msm::setting_option_name;
using msm::setting_range_text;

} // namespace msm::render
