// The declared render settings (msm/render/settings_schema.h) through the command line, the JSON
// outputs and view files: every setting, a value other than its default, comes back the same.
#include "reference_options.h"
#include "render_common.h"

#include "msm/reference/settings_schema.h"
#include "msm/render/settings_schema.h"
#include "msm/viewer/view_file.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
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
template <class Settings>
std::vector<json> other_values(const BasicSettingDeclaration<Settings>& setting) {
  const json fallback = setting.get(Settings{});
  std::vector<json> values;
  switch (setting.type) {
  case SettingType::number:
    for (double v : {setting.min, setting.max, 0.5 * (setting.min + setting.max)}) values.push_back(float(v));
    break;
  case SettingType::integer:
    for (double v : {setting.min, setting.max, 0.5 * (setting.min + setting.max)}) values.push_back(std::int64_t(v));
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

// What validate() says of a setting's value set straight into the settings (no check on the way):
// empty where it accepts it.
std::string validated(const SettingDeclaration& setting, const json& value) {
  render::RenderSettings settings;
  setting.set(settings, value);
  try {
    settings.validate();
  } catch (const render::RenderError& e) { return e.what(); }
  return {};
}

// The ranges are declared once: validate() accepts each number and integer setting at the ends of
// its declared range and refuses it just outside them, naming the setting, so that a range changed
// in the declaration alone changes what the renderer accepts.
TEST(CliSettings, ValidateRefusesExactlyOutsideEveryDeclaredRange) {
  for (const SettingDeclaration& setting : render::setting_declarations()) {
    if (setting.type != SettingType::number && setting.type != SettingType::integer) continue;
    SCOPED_TRACE(std::string(setting.key));
    std::vector<json> inside, outside;
    if (setting.type == SettingType::number) {
      const float lo = float(setting.min), hi = float(setting.max);
      inside = {lo, hi};
      outside = {std::nextafter(lo, -INFINITY), std::nextafter(hi, INFINITY)};
    } else {
      inside = {int(setting.min), int(setting.max)};
      outside = {int(setting.min) - 1, int(setting.max) + 1};
    }
    for (const json& value : inside) EXPECT_EQ(validated(setting, value), "") << value.dump();
    for (const json& value : outside) {
      const std::string error = validated(setting, value);
      EXPECT_TRUE(error.starts_with(fmt::format("{}: ", setting.key))) << value.dump() << ": '" << error << "'";
      EXPECT_NE(error.find(render::setting_range_text(setting)), std::string::npos) << error;
    }
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

// msm reference's options on `args` (after the required --effect, unless they give it): the
// settings, or the message of the error.
struct ParsedReference {
  reference::Settings settings;
  std::string error;
};
ParsedReference parse_reference(std::vector<std::string> args) {
  ReferenceOptions options;
  CLI::App app;
  add_reference_options(app.add_subcommand("reference"), options);
  if (std::find(args.begin(), args.end(), "--effect") == args.end()) args.insert(args.begin(), {"--effect", "soft"});
  args.insert(args.begin(), "reference");
  std::reverse(args.begin(), args.end()); // CLI11 takes them last first
  try {
    app.parse(args);
    return {reference_settings(options), ""};
  } catch (const std::exception& e) { return {{}, e.what()}; }
}

// The command line of one reference setting's value, as a user types it.
std::vector<std::string> reference_command_line(const reference::SettingDeclaration& setting, const json& value) {
  std::vector<std::string> args = {setting_option_name(setting)};
  if (setting.type != SettingType::flag)
    args.push_back(value.is_string()         ? value.get<std::string>()
                   : value.is_number_float() ? fmt::format("{}", value.get<double>())
                                             : value.dump());
  // What a value needs beside it: the effect it belongs to, a rectangle for its width and height.
  if (setting.key == "extracted_lights") args.insert(args.end(), {"--effect", "environment"});
  if (setting.key == "light_width_deg" || setting.key == "light_height_deg")
    args.insert(args.end(), {"--light-shape", "rectangle"});
  return args;
}

// Every reference setting, each value other than its default, from the command line through the
// JSON that msm reference writes (reference.json's settings) back to the settings: the same values.
TEST(CliSettings, EveryReferenceSettingGoesThroughCommandLineAndJsonUnchanged) {
  for (const reference::SettingDeclaration& setting : reference::setting_declarations()) {
    SCOPED_TRACE(std::string(setting.key));
    int tried = 0;
    for (const json& value : other_values(setting)) {
      const std::vector<std::string> args = reference_command_line(setting, value);
      const ParsedReference parsed = parse_reference(args);
      if (!parsed.error.empty()) {
        // Only a value that a rule across settings refuses (an even filter size) may be refused.
        EXPECT_NE(parsed.error.find("must be odd"), std::string::npos) << value.dump() << ": " << parsed.error;
        continue;
      }
      SCOPED_TRACE(value.dump());
      ++tried;
      const nlohmann::ordered_json written = reference::settings_json(parsed.settings);
      EXPECT_EQ(json(written[std::string(setting.key)]), value);
      // reference.json's text, read back into settings: every setting the same.
      reference::Settings back;
      reference::apply_settings_json(back, json::parse(written.dump(2)));
      EXPECT_EQ(reference::settings_json(back), written);
    }
    EXPECT_GT(tried, 0);
  }
}

TEST(CliSettings, ReferenceSettingsRefuseValuesAndKeysByTheirDeclarations) {
  EXPECT_EQ(parse_reference({"--width", "0"}).error, "width = 0 is outside [1, 16384] (--width)");
  EXPECT_EQ(parse_reference({"--effect", "sofft"}).error,
            "--effect sofft: use hard, filtered, soft, translucent, scattering or environment (did you mean soft?)");
  EXPECT_NE(parse_reference({"--samples", "many"}).error.find("--samples: expected an integer, got 'many'"),
            std::string::npos);
  reference::Settings settings;
  try {
    reference::apply_settings_json(settings, json::parse(R"({"width": 64, "filter_sise": 3})"));
    FAIL() << "accepted an unknown key";
  } catch (const SettingError& e) {
    EXPECT_EQ(e.pointer, "/filter_sise");
    EXPECT_TRUE(std::string(e.what()).starts_with("unknown setting (did you mean filter_size")) << e.what();
  }
}

} // namespace
} // namespace msm::tool
