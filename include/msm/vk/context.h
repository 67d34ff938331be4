// The Vulkan 1.3 instance, device and queue that everything else in msm::vk is created from.
#pragma once

#include "msm/vk/common.h"

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace msm::vk {

struct ValidationMessage {
  VkDebugUtilsMessageSeverityFlagBitsEXT severity; // WARNING or ERROR
  std::string id;                                  // message id name, e.g. "VUID-VkBufferMemoryBarrier2-offset-01187"
  std::string text;                                // the full message
};

// Every validation-layer (and loader) WARNING or ERROR a Context's messenger received; thread-safe.
// A Context hands it out as a shared_ptr so that what vkDestroyDevice/vkDestroyInstance report
// (leaked objects) can still be read once the Context is gone.
class ValidationLog {
 public:
  void add(ValidationMessage message);
  std::size_t count() const;
  std::vector<ValidationMessage> messages(std::size_t first = 0) const; // those from index `first` on
  void clear();
  // Print each message to stderr as it arrives (default on): a message appears next to the output
  // of the code that caused it. Tests that provoke messages on purpose turn it off.
  void set_echo(bool echo);
  static std::string format(const std::vector<ValidationMessage>& messages);

 private:
  mutable std::mutex mutex_;
  std::vector<ValidationMessage> messages_;
  bool echo_ = true;
};

struct ContextOptions {
  // Which physical device: "cpu" (lavapipe), "gpu" (first discrete, else integrated GPU), a decimal
  // index into vkEnumeratePhysicalDevices, or a case-insensitive substring of the device name.
  // Empty: the environment variable MSM_DEVICE, same syntax; if that is unset too, the first
  // discrete GPU, else the first integrated GPU, else any other suitable device (lavapipe).
  // Suitable: Vulkan 1.3, a compute queue, VK_KHR_push_descriptor. No match throws, listing devices.
  std::string device;
  // VK_LAYER_KHRONOS_validation + a VK_EXT_debug_utils messenger that records into validation().
  // Also turned on by MSM_VALIDATION=1 (or true/on/yes) for any program. A missing layer is not an
  // error here: it is reported on stderr and validation_enabled() is false (tests check that).
  bool validation = false;
  bool synchronization_validation = true; // with validation: the layer's hazard checks as well
  bool echo_validation = true;            // see ValidationLog::set_echo
  bool verbose = true;                    // one line on stderr naming the device picked
  // How msm_fma (shared.h) computes in the pipelines of this Context (use_native_fma()):
  //  Probe: the native fma() where the probe found it fused, else the exact emulation. With
  //         MSM_FORCE_EMULATED_FMA=1 (or true/on/yes) in the environment: Emulated;
  //  Emulated: the emulation even where fma() is fused (tests of the emulation on such devices);
  //  Native: the native fma() even where it is NOT fused (tests measuring what that costs).
  enum class FmaMode { probe, emulated, native };
  FmaMode fma_mode = FmaMode::probe;
  std::string application_name = "msm";
  // Extra extensions to enable, e.g. a window system's surface extensions (instance) and
  // VK_KHR_swapchain (device) for a viewer; a missing one fails the creation, naming it.
  std::vector<std::string> instance_extensions;
  std::vector<std::string> device_extensions;
};

struct DeviceInfo {
  uint32_t index = 0; // in vkEnumeratePhysicalDevices order
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::string driver_name; // e.g. "llvmpipe", "NVIDIA"
  std::string driver_info; // e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
  uint32_t api_version = 0;
  std::string describe() const; // one line with all of the above
};

// The features the device was created with: each is on where the device supports it (the list is in
// context.cpp). Vulkan 1.3 makes synchronization2, dynamicRendering and timelineSemaphore mandatory;
// shaderInt64, 16-bit storage, shaderFloat16, hostQueryReset etc. may be off. pNext members are null.
struct DeviceFeatures {
  VkPhysicalDeviceFeatures core{};
  VkPhysicalDeviceVulkan11Features v11{};
  VkPhysicalDeviceVulkan12Features v12{};
  VkPhysicalDeviceVulkan13Features v13{};
};

// Instance, physical device, device with one queue (graphics+compute where the device has such a
// family, else compute) and a command pool for one-shot submissions (submit_and_wait).
// Not copyable or movable (the messenger holds its address). Externally synchronized: use it from
// one thread at a time (the queue and the command pool are). Precondition for the destructor: every
// object created from it (Buffer, Image, Program, GpuTimer, ...) has been destroyed; the destructor
// waits for the device to be idle.
class Context {
 public:
  explicit Context(const ContextOptions& options = ContextOptions());
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const noexcept { return instance_; }
  VkPhysicalDevice physical_device() const noexcept { return physical_device_; }
  VkDevice device() const noexcept { return device_; }
  VkQueue queue() const noexcept { return queue_; }
  uint32_t queue_family() const noexcept { return queue_family_; }
  VkCommandPool command_pool() const noexcept { return command_pool_; }

  const DeviceInfo& info() const noexcept { return info_; }
  const DeviceFeatures& features() const noexcept { return features_; }
  const VkPhysicalDeviceProperties& properties() const noexcept { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memory_properties() const noexcept { return memory_; }
  // Of the queue's family: 0 means no timestamps (GpuTimer then measures nothing).
  uint32_t timestamp_valid_bits() const noexcept { return timestamp_valid_bits_; }

  // Whether the device's GLSL fma() is the fused multiply-add (one rounding), as found at creation
  // by the probe shader fma_probe.comp: on cases where one rounding, two roundings and a double
  // evaluation all differ, fused only if every case is rounded once. NVIDIA and AMD GPUs: fused;
  // lavapipe (llvmpipe): a * b, then + c.
  bool fused_fma() const noexcept { return fused_fma_; }
  // The value of the shared headers' specialization constant msm_fused_fma (shared.h,
  // MSM_SPEC_FUSED_FMA_ID) in every pipeline created from this Context: fused_fma(), unless
  // ContextOptions::fma_mode (or MSM_FORCE_EMULATED_FMA) says otherwise.
  bool use_native_fma() const noexcept { return use_native_fma_; }

  bool validation_enabled() const noexcept { return validation_; }
  ValidationLog& validation() const noexcept { return *log_; }
  std::shared_ptr<ValidationLog> validation_log() const noexcept { return log_; }

  // VK_KHR_push_descriptor entry points (device-level, loaded at creation).
  PFN_vkCmdPushDescriptorSetKHR cmd_push_descriptor_set() const noexcept { return push_descriptor_set_; }
  PFN_vkCmdPushDescriptorSetWithTemplateKHR cmd_push_descriptor_set_with_template() const noexcept {
    return push_descriptor_set_with_template_;
  }
  // Names an object in validation messages and debuggers; a no-op without validation.
  void set_object_name(VkObjectType type, uint64_t handle, const std::string& name) const;
  template <class Handle>
  void set_object_name(VkObjectType type, Handle handle, const std::string& name) const {
    set_object_name(type, (uint64_t)handle, name); // C cast: handles are pointers, or uint64_t on 32-bit
  }

 private:
  void destroy() noexcept;
  bool probe_fused_fma() const;

  // Validation, the instance and its debug messenger.
  bool validation_ = false;
  std::shared_ptr<ValidationLog> log_ = std::make_shared<ValidationLog>();
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger_ = nullptr;
  // The physical device, what it reports, the queue family chosen on it and its arithmetic.
  DeviceInfo info_;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  uint32_t queue_family_ = 0;
  uint32_t timestamp_valid_bits_ = 0;
  bool fused_fma_ = true;
  bool use_native_fma_ = true;
  // The device, the features it was created with, its queue, command pool and entry points.
  VkDevice device_ = VK_NULL_HANDLE;
  DeviceFeatures features_;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  PFN_vkCmdPushDescriptorSetKHR push_descriptor_set_ = nullptr;
  PFN_vkCmdPushDescriptorSetWithTemplateKHR push_descriptor_set_with_template_ = nullptr;
  PFN_vkSetDebugUtilsObjectNameEXT set_object_name_ = nullptr;
};

} // namespace msm::vk
