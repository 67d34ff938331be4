// Error handling and handle ownership shared by the msm::vk layer.
//
// Every failing Vulkan call throws msm::vk::Error (a std::runtime_error) naming the VkResult, the
// call and its source location: the layer never aborts, so a test reports the failure and moves on.
#pragma once

#include <vulkan/vulkan.h>

#include <source_location>
#include <stdexcept>
#include <string>
#include <utility>

namespace msm::vk {

// A Vulkan call that did not return VK_SUCCESS.
class Error : public std::runtime_error {
 public:
  Error(VkResult result, const std::string& what) : std::runtime_error(what), result_(result) {}
  VkResult result() const noexcept { return result_; }

 private:
  VkResult result_;
};

// "VK_ERROR_DEVICE_LOST"; "VkResult(<n>)" for a value this build does not know.
const char* result_name(VkResult result) noexcept;

[[noreturn]] void throw_error(VkResult result, const char* call, std::source_location where);

// Throws Error unless result is VK_SUCCESS. `where` defaults to the caller's location, which is the
// line of the MSM_VK_CHECK below. (Not VK_CHECK: a public header must not take that common name.)
inline void check(VkResult result, const char* call, std::source_location where = std::source_location::current()) {
  if (result != VK_SUCCESS) throw_error(result, call, where);
}

// Owns one device-level handle, destroyed with Destroy(device, handle, nullptr); move-only.
// Precondition: destroyed (or reset) before the VkDevice it was created on.
template <class Handle, void (*Destroy)(VkDevice, Handle, const VkAllocationCallbacks*)>
class Unique {
 public:
  Unique() = default;
  Unique(VkDevice device, Handle handle) noexcept : device_(device), handle_(handle) {}
  Unique(Unique&& other) noexcept
      : device_(other.device_), handle_(std::exchange(other.handle_, Handle(VK_NULL_HANDLE))) {}
  Unique& operator=(Unique&& other) noexcept {
    if (this != &other) {
      reset();
      device_ = other.device_;
      handle_ = std::exchange(other.handle_, Handle(VK_NULL_HANDLE));
    }
    return *this;
  }
  ~Unique() { reset(); }

  void reset() noexcept {
    if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }
  Handle get() const noexcept { return handle_; }
  operator Handle() const noexcept { return handle_; } // so that it passes where Vulkan wants the handle
  explicit operator bool() const noexcept { return handle_ != VK_NULL_HANDLE; }
  VkDevice device() const noexcept { return device_; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  Handle handle_ = VK_NULL_HANDLE;
};

using ImageView = Unique<VkImageView, vkDestroyImageView>;
using Sampler = Unique<VkSampler, vkDestroySampler>;
using ShaderModule = Unique<VkShaderModule, vkDestroyShaderModule>;
using Fence = Unique<VkFence, vkDestroyFence>;
using Semaphore = Unique<VkSemaphore, vkDestroySemaphore>;

} // namespace msm::vk

#define MSM_VK_CHECK(call) ::msm::vk::check((call), #call)
