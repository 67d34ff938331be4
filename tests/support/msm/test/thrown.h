// The message of an exception a test expects.
#pragma once
#include <gtest/gtest.h>

#include <string>

namespace msm::test {

// The message of the exception of type E that f() throws; a test failure, and "", where it throws
// none.
template <class E, class F>
std::string thrown_message(F&& f) {
  try {
    f();
  } catch (const E& e) { return e.what(); }
  ADD_FAILURE() << "no exception";
  return {};
}

} // namespace msm::test
