// The suites of `msm report`: which scenes are measured, against which ray-traced truth, with
// which techniques and settings. A suite is data: a scene, a light or a technique joins a suite
// as a row of its table (report_suite.cpp), and `msm report` measures every row the same way.
#pragma once

#include "msm/reference/reference.h"
#include "msm/scene/scene.h"

#include <optional>
#include <string>
#include <vector>

namespace msm::tool {

// One technique of a row, with the named parameters it is measured at ("NAME=VALUE", as --set
// takes them; none: the papers' defaults).
struct SuiteTechnique {
  std::string name;
  std::vector<std::string> parameters;
};

// One row: a scene rendered by every technique and traced by the ray tracer at one size.
struct SuiteRow {
  std::string id;    // names the row's images and its section of the page
  std::string scene; // a built-in scene, or a scene file relative to the source tree (scenes/NAME.json)
  // The ray-traced truth the techniques are measured against: filtered (the renderer's shadow map
  // and filter traced), soft (the scene's area light), scattering (the visible fraction of each
  // view ray, every pixel compared), environment (the whole light probe of the scene; compared is
  // the luminance of the tone-mapped images, the lights' extraction and the shadows together).
  reference::Effect truth = reference::Effect::filtered;
  int width = 320, height = 180, shadow_size = 512;
  int samples = 64; // of the truth, per pixel
  std::vector<SuiteTechnique> techniques;
  // Soft shadows: a disc light of this angular diameter in degrees instead of the scene's light,
  // in the renders and the truth alike.
  std::optional<float> light_extent_deg;
  // Image-based lighting: the scene's probe cut into this many area lights (default: the scene's).
  std::optional<int> probe_lights;
  // The scene under one light of this kind instead of its own lights (light_kinds.h: on its first
  // light's direction), in the renders and the truth alike; its name says which.
  std::optional<scene::LightKind> light_kind;
};

// Figures of the test suite itself: a test executable of the build run with a GoogleTest filter
// and MSM_TEST_FIGURES set, so that its tests write the figures their assertions check, with the
// bounds (tests/support/msm/test/figures.h). They join results.json under "tests".
struct SuiteTests {
  std::string title;      // what the figures are: the heading of their table
  std::string executable; // relative to the build directory (the CMake target's path)
  std::string filter;     // --gtest_filter
};

struct Suite {
  std::string name;
  std::string description;
  std::vector<SuiteRow> rows;
  int timed_frames = 3; // GPU time per pass: the median of this many frames after the first
  std::vector<SuiteTests> tests = {};
};

// The names of the declared suites, and one by name (UsageError naming the suites otherwise).
std::vector<std::string> suite_names();
const Suite& find_suite(const std::string& name);

} // namespace msm::tool
