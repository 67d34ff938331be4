// Fuzz target: mesh import (import_model: Assimp, then msm's conversion) of glTF, GLB, PLY, OFF
// and OBJ. The input is written to a file whose extension follows its content, as a user's file
// would be named: "glTF" magic: .glb; '{' first: .gltf; "ply": .ply; "OFF" (or COFF, NOFF, ...):
// .off; anything else: .obj.
#include "fuzz_support.h"
#include "msm/scene/scene.h"

#include <cmath>
#include <string_view>

namespace {

std::string extension_of(std::string_view text) {
  if (text.starts_with("glTF")) return ".glb";
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && text[first] == '{') return ".gltf";
  if (text.starts_with("ply")) return ".ply";
  const std::string_view head = text.substr(0, text.find_first_of(" \t\r\n"));
  if (head.ends_with("OFF")) return ".off";
  return ".obj";
}

void check_parts(const std::vector<msm::scene::ModelPart>& parts) {
  MSM_FUZZ_CHECK(!parts.empty());
  for (const msm::scene::ModelPart& part : parts) {
    const msm::scene::Mesh& m = part.mesh;
    MSM_FUZZ_CHECK(m.normals.size() == m.positions.size() && m.uvs.size() == m.positions.size());
    MSM_FUZZ_CHECK(!m.indices.empty() && m.indices.size() % 3 == 0);
    for (std::uint32_t i : m.indices) MSM_FUZZ_CHECK(i < m.positions.size());
    for (const glm::vec3& p : m.positions)
      MSM_FUZZ_CHECK(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    if (part.material) {
      (void)msm::scene::albedo_image(*part.material);
      (void)msm::scene::opacity_image(*part.material);
    }
  }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  msm::fuzz::lower_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::filesystem::path file = msm::fuzz::scratch_dir() / ("input" + extension_of(text));
  msm::fuzz::write_bytes(file, data, size);
  try {
    check_parts(msm::scene::import_model(file));
  } catch (const msm::scene::SceneError& e) { msm::fuzz::rejected(e); }
  std::filesystem::remove(file);
  return 0;
}
