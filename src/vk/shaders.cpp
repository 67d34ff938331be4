#include "msm/vk/shaders.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace msm::vk {
namespace {

struct Entry {
  std::string_view name;
  std::span<const uint32_t> code;
  std::string_view target;
  const EmbeddedShader* source; // identifies the registration that added it
};

// Function-local statics: registrations run during static initialization, in any order relative to
// this file's globals, so the registry is created on first use.
std::mutex& registry_mutex() {
  static std::mutex mutex;
  return mutex;
}
std::vector<Entry>& registry() {
  static std::vector<Entry> entries;
  return entries;
}

bool same_code(std::span<const uint32_t> a, std::span<const uint32_t> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

} // namespace

ShaderRegistration::ShaderRegistration(std::string_view target, std::span<const EmbeddedShader> shaders)
    : shaders_(shaders) {
  std::lock_guard lock(registry_mutex());
  for (const EmbeddedShader& shader : shaders) registry().push_back({shader.name, shader.code, target, &shader});
}

ShaderRegistration::~ShaderRegistration() {
  std::lock_guard lock(registry_mutex());
  std::erase_if(registry(), [&](const Entry& e) {
    return e.source >= shaders_.data() && e.source < shaders_.data() + shaders_.size();
  });
}

std::vector<std::string> embedded_shader_names() {
  std::lock_guard lock(registry_mutex());
  std::vector<std::string> names;
  for (const Entry& e : registry()) names.emplace_back(e.name);
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

std::span<const uint32_t> embedded_shader(std::string_view name) {
  std::span<const uint32_t> found;
  std::string_view found_target;
  {
    std::lock_guard lock(registry_mutex());
    for (const Entry& e : registry()) {
      if (e.name != name) continue;
      // The same file embedded by two targets (a library and its test) is the same shader.
      if (!found.empty() && !same_code(found, e.code))
        throw std::runtime_error(fmt::format("msm::vk::embedded_shader: '{}' is embedded by targets {} and {} with "
                                             "different code; rename one of them",
                                             name, found_target, e.target));
      found = e.code;
      found_target = e.target;
    }
  }
  if (found.empty())
    throw std::runtime_error(fmt::format("msm::vk::embedded_shader: no shader '{}' is embedded in this program "
                                         "(add it to msm_add_shaders() of a target it links); embedded: {}",
                                         name, fmt::join(embedded_shader_names(), ", ")));
  return found;
}

} // namespace msm::vk
