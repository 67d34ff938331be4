// msm reference's options: the declared settings of the ray tracer (msm/reference/settings_schema.h),
// one option each, and the options that are not settings of the tracing.
#pragma once

#include "msm/reference/reference.h"
#include "msm/scene/scene.h"
#include "setting_options.h"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace msm::tool {

// The options of msm reference, as given: the declared settings (msm/reference/settings_schema.h)
// by key, and what is not a setting of the tracing: the scene and its probe, where the outputs go,
// the threads (the images do not depend on them).
struct ReferenceOptions {
  GivenSettings given;
  std::string scene{msm::scene::default_scene_name()};
  std::string out = "out/reference";
  int threads = 0;
  std::string probe;             // a probe instead of the scene's lighting (scene::set_probe)
  std::optional<int> lights;     // the probe's area lights (scene::set_probe_light_count)
  std::optional<int> sub_lights; // and their sub-lights
  int frame = 0;                 // of a dynamic scene (msm render --frames)
  float probe_rotation_speed = 0.0f;
  bool json = false, progress = false, deprecated_probe_lights = false;
};

void add_reference_options(CLI::App* cmd, ReferenceOptions& options);
// The ray tracer's settings of the options; UsageError for a bad value.
msm::reference::Settings reference_settings(ReferenceOptions& options);

} // namespace msm::tool
