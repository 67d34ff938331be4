#include "setting_controls.h"

#include <algorithm>
#include <tuple>

namespace msm::viewer {

std::vector<SettingControl> setting_controls(const Technique& t) {
  std::vector<SettingControl> controls;
  for (const render::SettingDeclaration& setting : render::setting_declarations()) {
    SettingControl c{.setting = &setting, .kind = ControlKind::slider, .label = std::string(setting.key)};
    std::replace(c.label.begin(), c.label.end(), '_', ' ');
    std::tie(c.min, c.max) = render::setting_control_range(setting);
    c.logarithmic = setting.scale == SettingScale::logarithmic;
    c.step = std::max(setting.control_step, 1);
    switch (setting.type) {
    case SettingType::technique: c.kind = ControlKind::technique; break;
    case SettingType::parameters: c.kind = ControlKind::parameters; break;
    case SettingType::flag: c.kind = ControlKind::checkbox; break;
    case SettingType::choice: c.kind = ControlKind::combo; break;
    case SettingType::integer:
      c.kind = setting.nullable          ? ControlKind::optional
               : setting.choices.empty() ? ControlKind::slider
                                         : ControlKind::combo;
      break;
    case SettingType::number: c.kind = setting.nullable ? ControlKind::optional : ControlKind::slider; break;
    }
    // What the viewer decides itself, and what applies to some techniques only.
    if (setting.key == "width" || setting.key == "height") c.kind = ControlKind::window_size;
    if (setting.key == "light_extent_deg" || setting.key == "light_height_deg") {
      c.kind = ControlKind::light;
      c.enabled = t.area_light;
    }
    if (setting.key == "soft_kernel") {
      c.enabled = t.area_light;
      c.max = std::min(c.max, double(t.area_light ? t.max_soft_kernel : 0));
    }
    if (setting.key == "front_back_depth") c.enabled = t.soft();
    if (setting.key == "prefix_sums" || setting.key == "prefix_sum_mips") c.enabled = t.prefiltered_scattering();
    controls.push_back(c);
  }
  return controls;
}

double optional_start(const render::RenderSettings& s, const SettingControl& c) {
  if (c.setting->key == "depth_bias") return s.resolved_depth_bias();
  return c.min;
}

} // namespace msm::viewer
