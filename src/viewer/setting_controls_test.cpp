// The panel's controls are made from the render settings' declarations: every declared setting has
// one, for every technique, and a control offers only values its declaration accepts.
#include "setting_controls.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

namespace msm::viewer {
namespace {

TEST(SettingControls, EveryDeclaredSettingHasItsControlForEveryTechnique) {
  for (const Technique* t : render::rendered_techniques()) {
    SCOPED_TRACE(std::string(t->name));
    std::multiset<std::string> controlled;
    for (const SettingControl& c : setting_controls(*t)) controlled.insert(std::string(c.setting->key));
    std::multiset<std::string> declared;
    for (const render::SettingDeclaration& s : render::setting_declarations()) declared.insert(std::string(s.key));
    EXPECT_EQ(controlled, declared);
  }
}

// A slider's ends are the declaration's control range (a technique may narrow it), inside the
// declared range; each end and an integer slider's steps are values the declaration accepts.
TEST(SettingControls, SlidersOfferOnlyDeclaredValues) {
  int sliders = 0;
  for (const Technique* t : render::rendered_techniques()) {
    for (const SettingControl& c : setting_controls(*t)) {
      if (c.kind != ControlKind::slider && c.kind != ControlKind::optional) continue;
      SCOPED_TRACE(std::string(t->name) + " " + c.label);
      ++sliders;
      const render::SettingDeclaration& s = *c.setting;
      const auto [lo, hi] = render::setting_control_range(s);
      EXPECT_EQ(c.min, lo);
      EXPECT_LE(c.max, hi);
      EXPECT_EQ(c.logarithmic, s.scale == SettingScale::logarithmic);
      for (double v : {c.min, c.max}) {
        if (c.min > c.max) continue; // a setting the technique has not (greyed out)
        const nlohmann::json value = s.type == SettingType::integer ? nlohmann::json(int(v)) : nlohmann::json(float(v));
        EXPECT_NO_THROW(render::check_setting(s, value)) << value.dump();
      }
      if (s.type == SettingType::integer && c.step > 1) {
        render::RenderSettings settings;
        for (int v = int(c.min); v <= int(c.max); v += c.step) {
          s.set(settings, v);
          EXPECT_NO_THROW(settings.validate()) << v; // filter sizes: odd
        }
      }
    }
  }
  EXPECT_GT(sliders, 0);
}

// A setting whose default is null (it depends on the technique or the scene) gets the control that
// can hold "none" (a checkbox for its own value), never a slider that reads a number from null.
TEST(SettingControls, NullableSettingsGetTheOptionalControl) {
  const render::RenderSettings defaults;
  for (const SettingControl& c : setting_controls(render::find_rendered_technique("msm"))) {
    SCOPED_TRACE(c.label);
    if (c.kind == ControlKind::slider) EXPECT_FALSE(c.setting->get(defaults).is_null());
    if (c.setting->nullable && (c.setting->type == SettingType::number || c.setting->type == SettingType::integer))
      EXPECT_NE(c.kind, ControlKind::slider); // the optional control, or the light's own
  }
}

TEST(SettingControls, ChoicesAreTheDeclaredOnes) {
  const Technique& t = render::find_rendered_technique("msm");
  for (const SettingControl& c : setting_controls(t)) {
    SCOPED_TRACE(c.label);
    if (c.setting->type == SettingType::choice) EXPECT_EQ(c.kind, ControlKind::combo);
    if (c.setting->type == SettingType::flag) EXPECT_EQ(c.kind, ControlKind::checkbox);
    if (c.setting->type == SettingType::integer && !c.setting->choices.empty()) EXPECT_EQ(c.kind, ControlKind::combo);
  }
}

} // namespace
} // namespace msm::viewer
