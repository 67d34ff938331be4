// The scene tests' check of a refused scene: a SceneError whose message names every fragment.
#pragma once
#include "msm/scene/scene.h"

#include <gtest/gtest.h>

#include <exception>
#include <initializer_list>
#include <string>

namespace msm::test {

template <class F>
void expect_scene_error(F&& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    ADD_FAILURE() << "no SceneError thrown (expected one mentioning '" << *fragments.begin() << "')";
  } catch (const scene::SceneError& e) {
    const std::string what = e.what();
    for (const std::string& frag : fragments)
      EXPECT_NE(what.find(frag), std::string::npos) << "'" << frag << "' not in: " << what;
  } catch (const std::exception& e) { ADD_FAILURE() << "not a SceneError: " << e.what(); }
}

} // namespace msm::test
