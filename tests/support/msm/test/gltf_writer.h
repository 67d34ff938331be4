// Test support (not installed): writes small glTF 2.0 models, as .gltf with every buffer and
// picture in base64 data URIs (or pictures as PNG files beside it) or as a binary .glb, so that
// tests can build exactly the asset they need (materials, alpha modes, textures, several
// primitives on one mesh) instead of depending on a sample that has it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace msm::scene::testing {

struct GltfTexture {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba; // row 0 = the top row of the picture (texture coordinate v = 0)
};

struct GltfMaterial {
  std::string name;
  glm::vec4 base_color{1.0f};
  int texture = -1;                  // base colour texture (index into GltfModel::textures)
  std::string alpha_mode = "OPAQUE"; // OPAQUE, MASK, BLEND
  float alpha_cutoff = 0.5f;
  bool double_sided = false;
  float transmission = 0.0f; // KHR_materials_transmission's factor (0: not written)
  // KHR_texture_transform of the base colour texture (written where it is not the identity).
  glm::vec2 uv_offset{0.0f}, uv_scale{1.0f};
  float uv_rotation = 0.0f;
};

struct GltfPrimitive {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs; // glTF convention: (0, 0) the top-left of the picture
  std::vector<std::uint32_t> indices;
  int material = -1;
  int mode = 4; // glTF's primitive mode: 0 points, 1 lines, 4 triangles
};

// One mesh of all primitives, on one node.
struct GltfModel {
  std::vector<GltfPrimitive> primitives;
  std::vector<GltfMaterial> materials;
  std::vector<GltfTexture> textures;
  glm::vec3 translation{0.0f}; // of the node
};

// A quad: corner(s, t) = origin + s u + t v for s, t in {0, 1}, texture coordinate (s, t), facing
// `normal` (wound counter-clockwise around it).
GltfPrimitive quad(glm::vec3 origin, glm::vec3 u, glm::vec3 v, glm::vec3 normal, int material = -1);

// Four quads side by side along x, one per material, one of each alpha mode of glTF: "mask"
// (MASK with cutoff 0.3, alpha 0.9, the texture, double-sided), "blend" (BLEND, alpha 0.5),
// "opaque" (OPAQUE, the texture, an alpha of 0.2 to be ignored) and "glass" (transmission 0.8).
GltfModel alpha_modes_model(const GltfTexture& texture);

// .glb: one binary chunk; .gltf: data URIs, or with external_pictures PNG files "<stem>_<i>.png".
// Throws std::runtime_error if a file cannot be written.
void write_gltf(const std::filesystem::path& file, const GltfModel& model, bool external_pictures = false);

} // namespace msm::scene::testing
