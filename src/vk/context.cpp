#include "msm/vk/context.h"

#include "msm/vk/commands.h"
#include "msm/vk/program.h"
#include "msm/vk/resources.h"
#include "shaders/vk_bindings.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>

namespace msm::vk {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool env_flag(const char* name) {
  const char* value = std::getenv(name);
  if (!value) return false;
  std::string v = lower(value);
  return v == "1" || v == "true" || v == "on" || v == "yes";
}

bool contains(const std::vector<VkExtensionProperties>& list, const char* name) {
  return std::any_of(list.begin(), list.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkExtensionProperties> instance_extensions(const char* layer) {
  uint32_t count = 0;
  if (vkEnumerateInstanceExtensionProperties(layer, &count, nullptr) != VK_SUCCESS) return {};
  std::vector<VkExtensionProperties> list(count);
  if (vkEnumerateInstanceExtensionProperties(layer, &count, list.data()) < 0) return {};
  list.resize(count);
  return list;
}

bool has_layer(const char* name) {
  uint32_t count = 0;
  MSM_VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) < 0) return false;
  layers.resize(count);
  return std::any_of(layers.begin(), layers.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

const char* type_name(VkPhysicalDeviceType type) {
  switch (type) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
  case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
  default: return "other";
  }
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  static_cast<ValidationLog*>(user)->add(
      {severity, data->pMessageIdName ? data->pMessageIdName : "", data->pMessage ? data->pMessage : ""});
  return VK_FALSE; // the spec reserves VK_TRUE for layer development
}

struct Candidate {
  VkPhysicalDevice device;
  DeviceInfo info;
  uint32_t queue_family = 0;
  uint32_t timestamp_valid_bits = 0;
  std::string unsuitable; // why it cannot be used; empty if it can
};

Candidate inspect(VkPhysicalDevice device, uint32_t index) {
  Candidate c{.device = device};
  VkPhysicalDeviceDriverProperties driver{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceProperties2 props{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &driver};
  vkGetPhysicalDeviceProperties2(device, &props);
  c.info = {index,
            props.properties.deviceName,
            props.properties.deviceType,
            driver.driverName,
            driver.driverInfo,
            props.properties.apiVersion};

  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &family_count, families.data());
  // Graphics+compute first: the renderer draws shadow maps and filters them on one queue.
  int best = -1;
  for (uint32_t i = 0; i < family_count; ++i) {
    VkQueueFlags flags = families[i].queueFlags;
    if (!(flags & VK_QUEUE_COMPUTE_BIT)) continue;
    if (best < 0 || ((flags & VK_QUEUE_GRAPHICS_BIT) && !(families[best].queueFlags & VK_QUEUE_GRAPHICS_BIT)))
      best = int(i);
  }

  uint32_t ext_count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &ext_count, nullptr);
  std::vector<VkExtensionProperties> extensions(ext_count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &ext_count, extensions.data());
  extensions.resize(ext_count);

  if (props.properties.apiVersion < VK_API_VERSION_1_3)
    c.unsuitable = "Vulkan 1.3 not supported";
  else if (best < 0)
    c.unsuitable = "no compute queue";
  else if (!contains(extensions, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
    c.unsuitable = "no " VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
  else {
    c.queue_family = uint32_t(best);
    c.timestamp_valid_bits = families[best].timestampValidBits;
  }
  return c;
}

std::string list_devices(const std::vector<Candidate>& candidates) {
  std::string out;
  for (const Candidate& c : candidates)
    out += fmt::format("\n  {}: {}{}", c.info.index, c.info.describe(),
                       c.unsuitable.empty() ? "" : " [unsuitable: " + c.unsuitable + "]");
  return out.empty() ? "\n  (none)" : out;
}

// Index into candidates of the device the selector names (see ContextOptions::device).
size_t select(const std::vector<Candidate>& candidates, const std::string& selector, const char* source) {
  auto fail = [&](const std::string& why) -> size_t {
    throw std::runtime_error(fmt::format("msm::vk: {} (device selector '{}' from {}); devices:{}", why, selector,
                                         source, list_devices(candidates)));
  };
  auto usable = [&](size_t i) { return candidates[i].unsuitable.empty(); };
  auto first_of_type = [&](VkPhysicalDeviceType type) -> std::optional<size_t> {
    for (size_t i = 0; i < candidates.size(); ++i)
      if (usable(i) && candidates[i].info.type == type) return i;
    return std::nullopt;
  };

  if (selector.empty()) {
    for (VkPhysicalDeviceType type : {VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU})
      if (auto i = first_of_type(type)) return *i;
    for (size_t i = 0; i < candidates.size(); ++i)
      if (usable(i)) return i;
    return fail("no suitable Vulkan device (Vulkan 1.3, a compute queue, VK_KHR_push_descriptor)");
  }
  std::string wanted = lower(selector);
  if (wanted == "cpu") {
    if (auto i = first_of_type(VK_PHYSICAL_DEVICE_TYPE_CPU)) return *i;
    return fail("no suitable CPU device (install mesa-vulkan-drivers for lavapipe)");
  }
  if (wanted == "gpu") {
    for (VkPhysicalDeviceType type : {VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU})
      if (auto i = first_of_type(type)) return *i;
    return fail("no suitable discrete or integrated GPU");
  }
  size_t index = 0;
  auto [end, err] = std::from_chars(wanted.data(), wanted.data() + wanted.size(), index);
  if (err == std::errc() && end == wanted.data() + wanted.size()) {
    if (index >= candidates.size()) return fail(fmt::format("no device with index {}", index));
    if (!usable(index)) return fail(fmt::format("device {} is unsuitable: {}", index, candidates[index].unsuitable));
    return index;
  }
  for (size_t i = 0; i < candidates.size(); ++i)
    if (lower(candidates[i].info.name).find(wanted) != std::string::npos) {
      if (!usable(i)) return fail(fmt::format("device {} is unsuitable: {}", i, candidates[i].unsuitable));
      return i;
    }
  return fail("no device name contains it");
}

// Turns on every feature of this list that the device has. Why these: the shadow-map renderer and
// the moment math use them where present (64-bit/16-bit arithmetic and storage for the quantized
// moment formats, depth clamp for shadow casters behind the near plane, storage images without a
// format qualifier for the filters, min/max samplers and host query reset for the timers).
DeviceFeatures pick_features(VkPhysicalDevice device) {
  DeviceFeatures s;
  s.v13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  s.v12 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, .pNext = &s.v13};
  s.v11 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, .pNext = &s.v12};
  VkPhysicalDeviceFeatures2 f2{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &s.v11};
  vkGetPhysicalDeviceFeatures2(device, &f2);
  s.core = f2.features;

  DeviceFeatures e;
  e.v11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
  e.v12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  e.v13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
#define MSM_ENABLE(group, name) e.group.name = s.group.name
  MSM_ENABLE(core, shaderInt64);
  MSM_ENABLE(core, shaderInt16);
  MSM_ENABLE(core, shaderFloat64);
  MSM_ENABLE(core, depthClamp);
  MSM_ENABLE(core, depthBiasClamp);
  MSM_ENABLE(core, samplerAnisotropy);
  MSM_ENABLE(core, imageCubeArray);
  MSM_ENABLE(core, independentBlend);
  MSM_ENABLE(core, sampleRateShading);
  MSM_ENABLE(core, fillModeNonSolid);
  MSM_ENABLE(core, multiDrawIndirect);
  MSM_ENABLE(core, drawIndirectFirstInstance);
  MSM_ENABLE(core, fragmentStoresAndAtomics);
  MSM_ENABLE(core, shaderImageGatherExtended);
  MSM_ENABLE(core, shaderStorageImageExtendedFormats);
  MSM_ENABLE(core, shaderStorageImageReadWithoutFormat);
  MSM_ENABLE(core, shaderStorageImageWriteWithoutFormat);
  MSM_ENABLE(v11, storageBuffer16BitAccess);
  MSM_ENABLE(v11, uniformAndStorageBuffer16BitAccess);
  MSM_ENABLE(v11, storagePushConstant16);
  MSM_ENABLE(v11, shaderDrawParameters);
  MSM_ENABLE(v12, storageBuffer8BitAccess);
  MSM_ENABLE(v12, uniformAndStorageBuffer8BitAccess);
  MSM_ENABLE(v12, shaderFloat16);
  MSM_ENABLE(v12, shaderInt8);
  MSM_ENABLE(v12, drawIndirectCount);
  MSM_ENABLE(v12, samplerFilterMinmax);
  MSM_ENABLE(v12, scalarBlockLayout);
  MSM_ENABLE(v12, hostQueryReset);
  MSM_ENABLE(v12, timelineSemaphore);
  MSM_ENABLE(v13, synchronization2);
  MSM_ENABLE(v13, dynamicRendering);
  MSM_ENABLE(v13, maintenance4);
#undef MSM_ENABLE
  return e;
}

// Twice rounded: a * b to float, then + c (volatile: no contraction whatever the flags).
float unfused_fma(float a, float b, float c) {
  volatile float p = a * b;
  return p + c;
}

// The cases of the fma probe: a * b + c where the result rounded once (std::fma) and rounded twice
// (a * b to float, then + c) differ, and in some of them also a * b + c computed in double and then
// rounded to float (checked in probe_fused_fma, so a mistake here fails loudly). All results are
// normal floats: no flush to zero.
struct FmaCase {
  float a, b, c;
};
std::vector<FmaCase> fma_cases() {
  constexpr float p12 = 1.0f + 0x1p-12f, p20 = 1.0f + 0x1p-20f;
  return {
      {p12, p12, -1.0f},                            // 2^-11 + 2^-24; twice: 2^-11 (a tie, to even)
      {0.1f, 0.1f, -unfused_fma(0.1f, 0.1f, 0.0f)}, // the error of 0.1f², as in b2 - b1²; twice: 0
      {-p20, p20, 1.0f},                            // -(2^-19 + 2^-40); twice: -2^-19
      {p12, p12, 0x1p-70f},   // just above a tie: 1 + 2^-11 + 2^-23; twice and via double: 1 + 2^-11
      {-p12, p12, -0x1p-70f}, // the same, negative
      {0.7f, 1.3f, -unfused_fma(0.7f, 1.3f, 0.0f)}, // a product's rounding error
      {3.0f, 0x1.555556p-2f, -1.0f},                // 3 RN(1/3) - 1 = 2^-25; twice: 0
      {1.0e6f + 1.0f, 1.0e6f - 1.0f, -1.0e12f},     // 10^12 - 1 - RN(10^12) = 4095; twice: 0
  };
}

// The instance's layers and extensions: the validation layer where asked for and installed (else a
// warning and none), and the extensions the options name.
struct InstanceSetup {
  std::vector<const char*> layers, extensions;
  bool validation = false, sync_validation = false;
};

InstanceSetup instance_setup(const ContextOptions& options) {
  InstanceSetup setup;
  if (options.validation || env_flag("MSM_VALIDATION")) {
    std::vector<VkExtensionProperties> layer_extensions = instance_extensions(kValidationLayer);
    bool debug_utils = contains(instance_extensions(nullptr), VK_EXT_DEBUG_UTILS_EXTENSION_NAME) ||
                       contains(layer_extensions, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (!has_layer(kValidationLayer)) {
      std::fprintf(stderr,
                   "msm::vk: validation requested but %s is not installed (Debian: apt install "
                   "vulkan-validationlayers); running WITHOUT validation\n",
                   kValidationLayer);
    } else if (!debug_utils) {
      std::fprintf(stderr, "msm::vk: validation requested but " VK_EXT_DEBUG_UTILS_EXTENSION_NAME
                           " is missing; running WITHOUT validation\n");
    } else {
      setup.validation = true;
      setup.layers.push_back(kValidationLayer);
      setup.extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
      setup.sync_validation =
          options.synchronization_validation && contains(layer_extensions, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
      if (setup.sync_validation) setup.extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    }
  }
  for (const std::string& name : options.instance_extensions) {
    if (!contains(instance_extensions(nullptr), name.c_str()))
      throw std::runtime_error(fmt::format("msm::vk: the Vulkan instance lacks extension {}", name));
    setup.extensions.push_back(name.c_str());
  }
  return setup;
}

// Every warning and error, of every type, into `log`.
VkDebugUtilsMessengerCreateInfoEXT messenger_create_info(ValidationLog* log) {
  return {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
          .messageSeverity =
              VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
          .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
          .pfnUserCallback = on_message,
          .pUserData = log};
}

// A Vulkan 1.3 instance with `setup`'s layers and extensions; with validation, `messenger` (and with
// synchronization validation its feature) chained in.
VkInstance create_instance(const ContextOptions& options, const InstanceSetup& setup,
                           const VkDebugUtilsMessengerCreateInfoEXT& messenger) {
  VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT validation_features{.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
                                              .pNext = &messenger,
                                              .enabledValidationFeatureCount = 1,
                                              .pEnabledValidationFeatures = enables};
  VkApplicationInfo app{.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
                        .pApplicationName = options.application_name.c_str(),
                        .pEngineName = "msm",
                        .apiVersion = VK_API_VERSION_1_3};
  VkInstanceCreateInfo instance_info{
      .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
      .pNext = setup.validation ? (setup.sync_validation ? static_cast<const void*>(&validation_features) : &messenger)
                                : nullptr,
      .pApplicationInfo = &app,
      .enabledLayerCount = uint32_t(setup.layers.size()),
      .ppEnabledLayerNames = setup.layers.data(),
      .enabledExtensionCount = uint32_t(setup.extensions.size()),
      .ppEnabledExtensionNames = setup.extensions.data()};
  VkInstance instance = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateInstance(&instance_info, nullptr, &instance));
  return instance;
}

// The device that ContextOptions::device, else MSM_DEVICE, else the default policy selects.
Candidate choose_device(VkInstance instance, const ContextOptions& options) {
  uint32_t count = 0;
  MSM_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  MSM_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  std::vector<Candidate> candidates;
  for (uint32_t i = 0; i < count; ++i) candidates.push_back(inspect(devices[i], i));

  const char* source = "the default policy";
  std::string selector = options.device;
  if (!selector.empty())
    source = "ContextOptions::device";
  else if (const char* env = std::getenv("MSM_DEVICE"); env && *env) {
    selector = env;
    source = "MSM_DEVICE";
  }
  return candidates[select(candidates, selector, source)];
}

// The logical device: one queue of `queue_family`, `features` enabled, push descriptors and the
// extensions the options name (std::runtime_error naming the device where one is missing).
VkDevice create_device(VkPhysicalDevice physical_device, uint32_t queue_family, const DeviceFeatures& features,
                       const ContextOptions& options, const std::string& device_name) {
  DeviceFeatures chain = features;
  chain.v11.pNext = &chain.v12;
  chain.v12.pNext = &chain.v13;
  VkPhysicalDeviceFeatures2 features2{
      .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &chain.v11, .features = chain.core};
  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
                                     .queueFamilyIndex = queue_family,
                                     .queueCount = 1,
                                     .pQueuePriorities = &priority};
  std::vector<const char*> device_extensions = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  if (!options.device_extensions.empty()) {
    uint32_t ext_count = 0;
    vkEnumerateDeviceExtensionProperties(physical_device, nullptr, &ext_count, nullptr);
    std::vector<VkExtensionProperties> available(ext_count);
    vkEnumerateDeviceExtensionProperties(physical_device, nullptr, &ext_count, available.data());
    available.resize(ext_count);
    for (const std::string& name : options.device_extensions) {
      if (!contains(available, name.c_str()))
        throw std::runtime_error(fmt::format("msm::vk: {} lacks extension {}", device_name, name));
      device_extensions.push_back(name.c_str());
    }
  }
  VkDeviceCreateInfo device_info{.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
                                 .pNext = &features2,
                                 .queueCreateInfoCount = 1,
                                 .pQueueCreateInfos = &queue_info,
                                 .enabledExtensionCount = uint32_t(device_extensions.size()),
                                 .ppEnabledExtensionNames = device_extensions.data()};
  VkDevice device = VK_NULL_HANDLE;
  MSM_VK_CHECK(vkCreateDevice(physical_device, &device_info, nullptr, &device));
  return device;
}

// Whether msm_fma is the native fma(): as the probe found, unless the mode (or
// MSM_FORCE_EMULATED_FMA with the probing mode) forces one.
bool native_fma(ContextOptions::FmaMode mode, bool fused) {
  if (mode == ContextOptions::FmaMode::probe && env_flag("MSM_FORCE_EMULATED_FMA"))
    mode = ContextOptions::FmaMode::emulated;
  return mode == ContextOptions::FmaMode::native || (mode == ContextOptions::FmaMode::probe && fused);
}

} // namespace

void ValidationLog::add(ValidationMessage message) {
  std::lock_guard lock(mutex_);
  if (echo_)
    std::fprintf(stderr, "msm::vk validation %s: %s\n",
                 message.severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "ERROR" : "WARNING",
                 message.text.c_str());
  messages_.push_back(std::move(message));
}

std::size_t ValidationLog::count() const {
  std::lock_guard lock(mutex_);
  return messages_.size();
}

std::vector<ValidationMessage> ValidationLog::messages(std::size_t first) const {
  std::lock_guard lock(mutex_);
  if (first >= messages_.size()) return {};
  return {messages_.begin() + std::ptrdiff_t(first), messages_.end()};
}

void ValidationLog::clear() {
  std::lock_guard lock(mutex_);
  messages_.clear();
}

void ValidationLog::set_echo(bool echo) {
  std::lock_guard lock(mutex_);
  echo_ = echo;
}

std::string ValidationLog::format(const std::vector<ValidationMessage>& messages) {
  std::string out;
  for (const ValidationMessage& m : messages)
    out += fmt::format("[{}] {}\n", m.severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "ERROR" : "WARNING",
                       m.text);
  return out;
}

std::string DeviceInfo::describe() const {
  return fmt::format("{} ({}, driver {} {}, Vulkan {}.{}.{})", name, type_name(type), driver_name, driver_info,
                     VK_API_VERSION_MAJOR(api_version), VK_API_VERSION_MINOR(api_version),
                     VK_API_VERSION_PATCH(api_version));
}

Context::Context(const ContextOptions& options) {
  try {
    uint32_t loader_version = 0;
    MSM_VK_CHECK(vkEnumerateInstanceVersion(&loader_version));
    if (loader_version < VK_API_VERSION_1_3)
      throw std::runtime_error(fmt::format("msm::vk: the Vulkan loader supports {}.{}, 1.3 is needed",
                                           VK_API_VERSION_MAJOR(loader_version), VK_API_VERSION_MINOR(loader_version)));

    log_->set_echo(options.echo_validation);
    const InstanceSetup setup = instance_setup(options);
    validation_ = setup.validation;
    // The messenger is also chained into VkInstanceCreateInfo so that vkCreateInstance and
    // vkDestroyInstance are covered; it keeps a pointer to *log_, which outlives the instance.
    const VkDebugUtilsMessengerCreateInfoEXT messenger_info = messenger_create_info(log_.get());
    instance_ = create_instance(options, setup, messenger_info);
    if (validation_) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      destroy_messenger_ = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
      set_object_name_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
          vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
      if (!create || !destroy_messenger_) throw std::runtime_error("msm::vk: VK_EXT_debug_utils entry points missing");
      MSM_VK_CHECK(create(instance_, &messenger_info, nullptr, &messenger_));
    }

    const Candidate chosen = choose_device(instance_, options);
    physical_device_ = chosen.device;
    info_ = chosen.info;
    queue_family_ = chosen.queue_family;
    timestamp_valid_bits_ = chosen.timestamp_valid_bits;
    vkGetPhysicalDeviceProperties(physical_device_, &properties_);
    vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_);
    features_ = pick_features(physical_device_);
    device_ = create_device(physical_device_, queue_family_, features_, options, info_.name);
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

    push_descriptor_set_ =
        reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
    push_descriptor_set_with_template_ = reinterpret_cast<PFN_vkCmdPushDescriptorSetWithTemplateKHR>(
        vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetWithTemplateKHR"));
    if (!push_descriptor_set_ || !push_descriptor_set_with_template_)
      throw std::runtime_error("msm::vk: VK_KHR_push_descriptor entry points missing");

    VkCommandPoolCreateInfo pool_info{.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                      .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT,
                                      .queueFamilyIndex = queue_family_};
    MSM_VK_CHECK(vkCreateCommandPool(device_, &pool_info, nullptr, &command_pool_));

    fused_fma_ = probe_fused_fma();
    use_native_fma_ = native_fma(options.fma_mode, fused_fma_);
    if (options.verbose)
      std::fprintf(stderr, "msm::vk: device %u: %s; validation %s; fma() %s, msm_fma %s\n", info_.index,
                   info_.describe().c_str(),
                   validation_ ? (setup.sync_validation ? "on (+synchronization)" : "on") : "off",
                   fused_fma_ ? "fused" : "NOT fused",
                   use_native_fma_ ? (fused_fma_ ? "native" : "native (forced, NOT exact)")
                                   : (fused_fma_ ? "emulated (forced)" : "emulated"));
  } catch (...) {
    destroy();
    throw;
  }
}

Context::~Context() { destroy(); }

void Context::destroy() noexcept {
  if (device_) {
    vkDeviceWaitIdle(device_); // nothing to do about a failure in a destructor; destruction goes on
    if (command_pool_) vkDestroyCommandPool(device_, command_pool_, nullptr);
    vkDestroyDevice(device_, nullptr); // the layer reports objects still alive here, into *log_
  }
  if (messenger_) destroy_messenger_(instance_, messenger_, nullptr);
  if (instance_) vkDestroyInstance(instance_, nullptr);
  command_pool_ = VK_NULL_HANDLE;
  device_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

// Runs fma_probe.comp over kFmaCases (see there): fused if every case, in both of the shader's
// forms, comes back rounded once. Anything else (twice rounded, evaluated in double, mixed): not.
bool Context::probe_fused_fma() const {
  const std::vector<FmaCase> cases = fma_cases();
  const uint32_t n = uint32_t(cases.size());
  std::vector<float> words(4 * 3 * n, 0.0f); // vec4 per case: (a, b, c, 0) twice, then the results
  bool catches_double = false;
  for (uint32_t i = 0; i < n; ++i) {
    const FmaCase& k = cases[i];
    float fused = std::fma(k.a, k.b, k.c);
    if (fused == unfused_fma(k.a, k.b, k.c) || !std::isnormal(fused))
      throw std::logic_error(fmt::format("msm::vk: fma probe case {} does not tell fused from unfused", i));
    catches_double |= fused != float(double(k.a) * double(k.b) + double(k.c));
    for (uint32_t copy = 0; copy < 2; ++copy) {
      float* v = &words[4 * (copy * n + i)];
      v[0] = k.a, v[1] = k.b, v[2] = k.c;
    }
  }
  if (!catches_double) throw std::logic_error("msm::vk: no fma probe case tells fused from computed in double");
  VkDeviceSize size = words.size() * sizeof(float);
  Buffer buffer = create_buffer(*this, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::host);
  std::memcpy(buffer.data(), words.data(), size);
  Program probe = create_program(*this, "fma_probe", {{MSM_BINDING_FMA_PROBE_CASES, Binding::storage_buffer}});
  submit_and_wait(*this, [&](VkCommandBuffer cmd) {
    dispatch(cmd, probe, group_count(n, 64), 1, 1, {{MSM_BINDING_FMA_PROBE_CASES, buffer}});
  });
  std::memcpy(words.data(), buffer.data(), size);
  for (uint32_t i = 0; i < n; ++i) {
    float fused = std::fma(cases[i].a, cases[i].b, cases[i].c);
    const float* out = &words[4 * (2 * n + i)];
    for (int form = 0; form < 2; ++form)
      if (std::bit_cast<uint32_t>(out[form]) != std::bit_cast<uint32_t>(fused)) return false;
  }
  return true;
}

void Context::set_object_name(VkObjectType type, uint64_t handle, const std::string& name) const {
  if (!set_object_name_ || !handle) return;
  VkDebugUtilsObjectNameInfoEXT info{.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT,
                                     .objectType = type,
                                     .objectHandle = handle,
                                     .pObjectName = name.c_str()};
  MSM_VK_CHECK(set_object_name_(device_, &info));
}

} // namespace msm::vk
