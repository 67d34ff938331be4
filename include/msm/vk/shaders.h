// SPIR-V embedded at build time by msm_add_shaders() (cmake/MsmShaders.cmake).
//
// Each target that calls msm_add_shaders(TARGET t SOURCES a.comp b.vert ...) gets one generated
// source in which every shader is a `const uint32_t[]` (glslc -mfmt=num) and a static
// ShaderRegistration object that adds them to the one process-wide registry below. The arrays have
// internal linkage, so any number of targets in one program never clash; the only external symbol
// is `msm_shaders_anchor_<t>`, which consumers of a static library are linked with
// --undefined=<it> so that the linker keeps the registering object file.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace msm::vk {

// The SPIR-V of an embedded shader. Names: the file name ("shadow.vert", "selftest.comp") and, where
// no other shader of the same msm_add_shaders() call has the same stem, the stem ("selftest").
// Throws std::runtime_error naming the shader and listing the embedded ones if it is unknown, or if
// two targets embed different code under that name.
std::span<const uint32_t> embedded_shader(std::string_view name);

// Every name embedded_shader() knows, sorted.
std::vector<std::string> embedded_shader_names();

// --- used by the generated code ---
struct EmbeddedShader {
  std::string_view name;
  std::span<const uint32_t> code;
};

// Registers shaders (static storage, outliving this object) for target `target`; unregisters them
// on destruction (a shared library being unloaded).
class ShaderRegistration {
 public:
  ShaderRegistration(std::string_view target, std::span<const EmbeddedShader> shaders);
  ~ShaderRegistration();
  ShaderRegistration(const ShaderRegistration&) = delete;
  ShaderRegistration& operator=(const ShaderRegistration&) = delete;

 private:
  std::span<const EmbeddedShader> shaders_;
};

} // namespace msm::vk
