// The declared render settings (msm/render/settings_schema.h) through the command line, the JSON
// outputs and view files: every setting, a value other than its default, comes back the same.
#include "render_common.h"

#include "msm/render/settings_schema.h"
#include "msm/viewer/view_file.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace msm::tool {
namespace {

using nlohmann::json;
using render::SettingDeclaration;
using render::SettingType;

// Values of a setting other than its default, from its declaration: the ends and the middle of a
// range, the other choices, the other flag value, the other techniques.
std::vector<json> other_values(const SettingDeclaration& setting) {
  const json fallback = setting.get(render::RenderSettings{});
  std::vector<json> values;
  switch (setting.type) {
  case SettingType::number:
    for (double v : {setting.min, setting.max, 0.5 * (setting.min + setting.max)}) values.push_back(float(v));
    break;
  case SettingType::integer:
    for (double v : {setting.min, setting.max, 0.5 * (setting.min + setting.max)}) values.push_back(int(v));
    break;
  case SettingType::flag: values.push_back(!fallback.get<bool>()); break;
  case SettingType::choice:
    for (std::string_view choice : setting.choices) values.push_back(std::string(choice));
    break;
  case SettingType::technique:
    for (const Technique* t : render::rendered_techniques()) values.push_back(std::string(t->name));
    break;
  case SettingType::parameters:
    for (const Technique* t : render::rendered_techniques())
      for (const Parameter* p : t->parameter_list()) {
        json value = p->type == ParameterType::choice    ? json(std::string(p->choices.back().name))
                     : p->type == ParameterType::flag    ? json(p->default_value == 0.0f)
                     : p->type == ParameterType::integer ? json(int(p->max))
                                                         : json(!std::isfinite(p->max) ? p->default_value + 1.0f
                                                                : p->max_open          ? 0.5f * (p->min + p->max)
                                                                                       : p->max);
        values.push_back({{"technique", std::string(t->name)}, {"name", std::string(p->name)}, {"value", value}});
      }
    break;
  }
  std::erase(values, fallback);
  return values;
}

// The command line of one setting's value, as a user types it.
std::vector<std::string> command_line(const SettingDeclaration& setting, const json& value) {
  if (setting.type == SettingType::flag) return {render::setting_option_name(setting)};
  if (setting.type == SettingType::parameters) {
    const json& v = value["value"];
    return {"--set", fmt::format("{}={}", value["name"].get<std::string>(),
                                 v.is_string()    ? v.get<std::string>()
                                 : v.is_boolean() ? (v.get<bool>() ? "on" : "off")
                                                  : v.dump())};
  }
  if (setting.type == SettingType::number)
    return {render::setting_option_name(setting), fmt::format("{}", value.get<float>())};
  if (setting.type == SettingType::technique) return {};
  return {render::setting_option_name(setting), value.is_string() ? value.get<std::string>() : value.dump()};
}

struct Parsed {
  render::RenderSettings settings;
  std::string error;
};

// msm render's frame options on `args`, the settings of `technique` (as -t gives it).
Parsed parse(const std::vector<std::string>& args, const std::string& technique) {
  FrameOptions options;
  CLI::App app;
  add_frame_options(app.add_subcommand("render"), options);
  std::vector<std::string> argv = {"render"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::reverse(argv.begin(), argv.end()); // CLI11 takes them last first
  try {
    app.parse(argv);
    finish_frame_options(options);
    Parsed parsed{settings_for(options, technique), ""};
    parsed.settings.validate();
    return parsed;
  } catch (const std::exception& e) { return {{}, e.what()}; }
}

// The first technique (the default first) with which a value of a setting is valid.
std::optional<std::string> technique_for(const SettingDeclaration& setting, const json& value) {
  std::vector<std::string> names = {render::RenderSettings{}.technique};
  for (const Technique* t : render::rendered_techniques()) names.emplace_back(t->name);
  if (setting.type == SettingType::technique) names = {value.get<std::string>()};
  if (setting.type == SettingType::parameters) names = {value["technique"].get<std::string>()};
  for (const std::string& name : names)
    if (parse(command_line(setting, value), name).error.empty()) return name;
  return std::nullopt;
}

TEST(CliSettings, EverySettingGoesThroughCommandLineJsonAndViewFileUnchanged) {
  for (const SettingDeclaration& setting : render::setting_declarations()) {
    SCOPED_TRACE(std::string(setting.key));
    int tried = 0;
    for (const json& value : other_values(setting)) {
      const std::optional<std::string> technique = technique_for(setting, value);
      if (!technique) continue;
      SCOPED_TRACE(fmt::format("{} with {}", value.dump(), *technique));
      ++tried;
      const Parsed parsed = parse(command_line(setting, value), *technique);
      ASSERT_EQ(parsed.error, "");
      // What the command line set, in the JSON output under the setting's key.
      const json out = render::settings_json(parsed.settings);
      if (setting.type == SettingType::parameters)
        EXPECT_EQ(out["parameters"][value["name"].get<std::string>()], value["value"]);
      else
        EXPECT_EQ(out[std::string(setting.key)], value);
      // The JSON output's view, read back as a view file: every setting the same.
      viewer::View view;
      view.settings = parsed.settings;
      const viewer::View back = viewer::parse_view(viewer::view_json(view).dump(2), "round-trip.json");
      EXPECT_EQ(render::settings_json(back.settings), out);
    }
    // Every setting is covered: at least one value other than its default is valid.
    EXPECT_GT(tried, 0);
  }
}

TEST(CliSettings, EveryDeclaredSettingHasItsOption) {
  FrameOptions options;
  CLI::App app;
  CLI::App* cmd = app.add_subcommand("render");
  add_frame_options(cmd, options);
  for (const SettingDeclaration& setting : render::setting_declarations()) {
    if (setting.type == SettingType::technique || setting.type == SettingType::parameters) continue;
    const std::string name = render::setting_option_name(setting);
    EXPECT_NO_THROW(cmd->get_option(name)) << name;
  }
}

TEST(CliSettings, RefusedValuesNameTheOptionAndTheRange) {
  EXPECT_EQ(parse({"--width", "0"}, "msm").error, "width = 0 is outside [1, 16384] (--width)");
  EXPECT_EQ(parse({"--lookup", "bilinar"}, "msm").error,
            "--lookup bilinar: use auto, bilinear, nearest or dither (did you mean bilinear?)");
  EXPECT_NE(parse({"--msaa", "four"}, "msm").error.find("--msaa: expected an integer, got 'four'"), std::string::npos);
}

TEST(CliSettings, UnknownKeyInAViewFileNamesItsPointerAndTheNearest) {
  try {
    viewer::parse_view(R"({"msm_view": 1, "settings": {"filter_sise": 3}})", "bad.json");
    FAIL() << "accepted an unknown key";
  } catch (const viewer::ViewError& e) {
    EXPECT_TRUE(
        std::string(e.what()).starts_with("bad.json: /settings/filter_sise: unknown setting (did you mean filter_size"))
        << e.what();
  }
  try {
    viewer::parse_view(R"({"msm_view": 1, "settings": {"width": 0}})", "bad.json");
    FAIL() << "accepted a width of 0";
  } catch (const viewer::ViewError& e) {
    EXPECT_EQ(std::string(e.what()), "bad.json: /settings/width: 0 is outside [1, 16384]");
  }
}

} // namespace
} // namespace msm::tool
