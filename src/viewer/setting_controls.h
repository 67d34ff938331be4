// The panel's controls of the render settings, made from their declarations
// (msm/render/settings_schema.h): one per declared setting, its range, choices and meaning (the
// tooltip) the declaration's, so that a setting added to the table gets its control. The panel
// draws this list (panel.cpp); its test walks it against the table.
#pragma once

#include "msm/render/settings_schema.h"
#include "msm/techniques.h"

#include <string>
#include <vector>

namespace msm::viewer {

enum class ControlKind {
  technique,   // the technique's combo (with the scene's, at the top of the panel)
  parameters,  // a widget per parameter the technique declares (msm techniques NAME)
  window_size, // shown, not set: the image is the window's size
  light,       // the light's shape and extents against the scene's light (one group for both keys)
  slider,      // a number or an integer over [min, max]
  checkbox,    // a flag
  combo,       // a choice, or an integer with listed values
  optional,    // a nullable number or integer: a checkbox for "own value", then its slider
};

struct SettingControl {
  const render::SettingDeclaration* setting;
  ControlKind kind;
  std::string label;        // the key, with spaces
  double min = 0, max = 0;  // slider, optional: the range it offers, inside the declared one
  bool logarithmic = false; //
  int step = 1;             // an integer slider's step from min
  bool enabled = true;      // the setting applies to the technique (else shown greyed out)
};

// Every declared setting's control for the technique, in the table's order.
std::vector<SettingControl> setting_controls(const Technique& technique);
// An optional control's value when its own value is turned on: what the default resolves to
// (the technique's depth bias), else the least the control offers.
double optional_start(const render::RenderSettings& settings, const SettingControl& control);

} // namespace msm::viewer
