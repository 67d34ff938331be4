// What the renderer's tests render: the settings as the tests state them, and lists of techniques
// taken from the technique table.
#pragma once
#include "msm/cpu/techniques.h"
#include "msm/render/renderer.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace msm::test {

// A technique at an image and shadow-map size, every other setting at its default (the caller
// changes what its test is about).
inline render::RenderSettings render_settings(std::string technique, int width, int height, int shadow_size) {
  render::RenderSettings s;
  s.technique = std::move(technique);
  s.width = width;
  s.height = height;
  s.shadow_size = shadow_size;
  return s;
}

// Every single-scattering technique of the technique table, in table order (call it from a test,
// not from a static initializer: the table is itself a static object of another translation unit).
inline std::vector<std::string> scattering_techniques() {
  std::vector<std::string> names;
  for (const Technique& t : techniques())
    if (t.scatters()) names.emplace_back(t.name);
  if (names.empty()) ADD_FAILURE() << "the technique table lists no scattering technique";
  return names;
}

} // namespace msm::test
