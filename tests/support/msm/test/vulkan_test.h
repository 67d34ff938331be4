// GoogleTest support for tests that run on a Vulkan device with the validation layer on.
//
//   class MyTest : public msm::vk::test::VulkanTest {};
//   TEST_F(MyTest, Works) { msm::vk::Buffer b = msm::vk::create_buffer(ctx(), ...); ... }
//
// Every VulkanTest shares one Context per test program (device from MSM_DEVICE, validation on),
// created on first use. A test fails if the validation layer reported any WARNING or ERROR during
// it, and the program fails if destroying the Context at the end reports something (objects not
// destroyed). A missing validation layer fails every test, unless MSM_ALLOW_NO_VALIDATION=1 (then
// the tests run unchecked).
// Header-only: the test target links GTest (msm_add_test does), msm::vk does not.
#pragma once

#include "msm/vk/context.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <exception>
#include <memory>
#include <string>

namespace msm::vk::test {

inline bool allow_no_validation() {
  const char* v = std::getenv("MSM_ALLOW_NO_VALIDATION");
  return v && std::string(v) == "1";
}

// What every test context uses: validation on (and echoed), the device from MSM_DEVICE.
inline ContextOptions test_options() {
  ContextOptions options;
  options.validation = true;
  return options;
}

// Success if `log` holds no message from index `first` on; else lists them.
inline ::testing::AssertionResult no_validation_messages(const ValidationLog& log, std::size_t first = 0) {
  std::vector<ValidationMessage> messages = log.messages(first);
  if (messages.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << messages.size() << " validation message(s):\n"
                                       << ValidationLog::format(messages);
}

// Success if validation is on, or allowed to be off.
inline ::testing::AssertionResult validation_active(const Context& ctx) {
  if (ctx.validation_enabled() || allow_no_validation()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "the Vulkan validation layer is not active (is vulkan-validationlayers "
                                          "installed?); set MSM_ALLOW_NO_VALIDATION=1 to run without it";
}

// Owns the shared Context; a gtest Environment so that its TearDown (after the last test) destroys
// the Context while failures can still be reported.
class SharedContext : public ::testing::Environment {
 public:
  static SharedContext& instance() {
    static SharedContext* environment =
        static_cast<SharedContext*>(::testing::AddGlobalTestEnvironment(new SharedContext));
    return *environment;
  }

  // Throws (the first failure again) if the Context cannot be created.
  Context& get() {
    if (!context_ && error_.empty()) {
      try {
        context_ = std::make_unique<Context>(test_options());
        log_ = context_->validation_log();
      } catch (const std::exception& e) { error_ = e.what(); }
    }
    if (!context_) throw std::runtime_error("no Vulkan context: " + error_);
    return *context_;
  }

  void TearDown() override {
    if (!context_) return;
    std::size_t first = log_->count();
    context_.reset(); // vkDestroyDevice reports objects that were never destroyed
    EXPECT_TRUE(no_validation_messages(*log_, first)) << "while destroying the shared Vulkan context";
  }

 private:
  std::unique_ptr<Context> context_;
  std::shared_ptr<ValidationLog> log_;
  std::string error_;
};

// Registered with gtest before main() runs (gtest_main calls RUN_ALL_TESTS, which runs TearDown).
inline SharedContext& shared_context_registration = SharedContext::instance();

class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      ctx_ = &SharedContext::instance().get();
    } catch (const std::exception& e) { FAIL() << e.what(); }
    ASSERT_TRUE(validation_active(*ctx_));
    first_ = ctx_->validation().count();
  }
  void TearDown() override {
    if (ctx_) { EXPECT_TRUE(no_validation_messages(ctx_->validation(), first_)) << "during this test"; }
  }

  Context& ctx() { return *ctx_; }

 private:
  Context* ctx_ = nullptr;
  std::size_t first_ = 0;
};

} // namespace msm::vk::test
