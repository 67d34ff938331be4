#include "msm/vk/common.h"

#include <fmt/format.h>

namespace msm::vk {

const char* result_name(VkResult result) noexcept {
  switch (result) {
#define MSM_CASE(name)                                                                                                 \
  case name: return #name;
    MSM_CASE(VK_SUCCESS)
    MSM_CASE(VK_NOT_READY)
    MSM_CASE(VK_TIMEOUT)
    MSM_CASE(VK_EVENT_SET)
    MSM_CASE(VK_EVENT_RESET)
    MSM_CASE(VK_INCOMPLETE)
    MSM_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    MSM_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    MSM_CASE(VK_ERROR_INITIALIZATION_FAILED)
    MSM_CASE(VK_ERROR_DEVICE_LOST)
    MSM_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    MSM_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    MSM_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    MSM_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    MSM_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    MSM_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    MSM_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    MSM_CASE(VK_ERROR_FRAGMENTED_POOL)
    MSM_CASE(VK_ERROR_UNKNOWN)
    MSM_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    MSM_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    MSM_CASE(VK_ERROR_FRAGMENTATION)
    MSM_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    MSM_CASE(VK_PIPELINE_COMPILE_REQUIRED)
    MSM_CASE(VK_ERROR_SURFACE_LOST_KHR)
    MSM_CASE(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    MSM_CASE(VK_SUBOPTIMAL_KHR)
    MSM_CASE(VK_ERROR_OUT_OF_DATE_KHR)
    MSM_CASE(VK_ERROR_INCOMPATIBLE_DISPLAY_KHR)
    MSM_CASE(VK_ERROR_VALIDATION_FAILED_EXT)
    MSM_CASE(VK_ERROR_INVALID_SHADER_NV)
    MSM_CASE(VK_ERROR_INVALID_DRM_FORMAT_MODIFIER_PLANE_LAYOUT_EXT)
    MSM_CASE(VK_ERROR_NOT_PERMITTED_KHR)
    MSM_CASE(VK_ERROR_FULL_SCREEN_EXCLUSIVE_MODE_LOST_EXT)
    MSM_CASE(VK_THREAD_IDLE_KHR)
    MSM_CASE(VK_THREAD_DONE_KHR)
    MSM_CASE(VK_OPERATION_DEFERRED_KHR)
    MSM_CASE(VK_OPERATION_NOT_DEFERRED_KHR)
    MSM_CASE(VK_ERROR_COMPRESSION_EXHAUSTED_EXT)
#undef MSM_CASE
  default: break;
  }
  // Unknown values: a thread-local buffer keeps this noexcept and allocation-free.
  thread_local char buffer[32];
  fmt::format_to_n(buffer, sizeof(buffer) - 1, "VkResult({})", int(result)).out[0] = '\0';
  return buffer;
}

void throw_error(VkResult result, const char* call, std::source_location where) {
  // What a user can act on first; the call and its place for a bug report.
  const char* meaning = result == VK_ERROR_DEVICE_LOST ? "the device was lost (a driver timeout or reset, or a GPU "
                                                         "fault; what was not yet written is lost): "
                        : result == VK_ERROR_OUT_OF_DEVICE_MEMORY ? "the device is out of memory: "
                        : result == VK_ERROR_OUT_OF_HOST_MEMORY   ? "out of host memory: "
                                                                  : "";
  throw Error(result, fmt::format("{}{} failed: {} at {}:{} ({})", meaning, call, result_name(result),
                                  where.file_name(), where.line(), where.function_name()));
}

} // namespace msm::vk
