// Mesh import through Assimp, and minimal texture loading through stb_image.
#include <algorithm>
#include <cmath>
#include <system_error>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#define STB_IMAGE_STATIC // private copy: no clash with a libstb linked by the application
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include "internal.h"

namespace msm::scene {
namespace {

void check_regular_file(const std::filesystem::path& file, const char* what) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec || !std::filesystem::exists(status))
    throw SceneError(file.string(), "", fmt::format("{} file does not exist", what));
  if (!std::filesystem::is_regular_file(status))
    throw SceneError(file.string(), "", fmt::format("{} path is not a regular file", what));
}

} // namespace

Mesh import_mesh(const std::filesystem::path& file) {
  check_regular_file(file, "mesh");
  Assimp::Importer importer;
  // Points and lines are removed; only triangles are kept.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                         aiProcess_GenSmoothNormals | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  const aiScene* s = importer.ReadFile(file.string(), flags);
  if (!s || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !s->mRootNode)
    throw SceneError(file.string(), "", fmt::format("Assimp cannot read the mesh: {}", importer.GetErrorString()));
  Mesh m;
  for (unsigned mi = 0; mi < s->mNumMeshes; ++mi) {
    const aiMesh* am = s->mMeshes[mi];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || !am->mVertices) continue;
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      m.positions.emplace_back(p.x, p.y, p.z);
      m.normals.push_back(am->mNormals ? glm::vec3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z)
                                       : glm::vec3(0.0f));
      m.uvs.push_back(am->mTextureCoords[0] ? glm::vec2(am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y)
                                            : glm::vec2(0.0f));
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) m.indices.push_back(base + face.mIndices[k]);
    }
  }
  if (m.indices.empty()) throw SceneError(file.string(), "", "the mesh file contains no triangles");
  try {
    detail::finalize_mesh(m, "");
  } catch (const SceneError& e) { throw SceneError(file.string(), "", e.problem()); }
  return m;
}

Image load_texture(const std::filesystem::path& file) {
  check_regular_file(file, "texture");
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load(file.string().c_str(), &w, &h, &channels, 4);
  if (!data) throw SceneError(file.string(), "", fmt::format("cannot decode the image: {}", stbi_failure_reason()));
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(data, data + std::size_t(w) * h * 4);
  stbi_image_free(data);
  return img;
}

} // namespace msm::scene

namespace msm::scene {

float OpacityImage::sample(glm::vec2 uv) const {
  if (width == 0) return 1.0f;
  // Texel centres at (i + 0.5) / width, repeat: as a Vulkan linear sampler with REPEAT.
  float x = uv.x * float(width) - 0.5f, y = uv.y * float(height) - 0.5f;
  float fx = std::floor(x), fy = std::floor(y);
  auto at = [&](int i, int j) {
    i = ((i % width) + width) % width;
    j = ((j % height) + height) % height;
    return float(values[std::size_t(j) * std::size_t(width) + std::size_t(i)]) / 255.0f;
  };
  int i = int(fx), j = int(fy);
  float tx = x - fx, ty = y - fy;
  return (1 - ty) * ((1 - tx) * at(i, j) + tx * at(i + 1, j)) + ty * ((1 - tx) * at(i, j + 1) + tx * at(i + 1, j + 1));
}

OpacityImage opacity_image(const Material& material) {
  if (material.opacity_noise) return make_smoke_opacity(*material.opacity_noise);
  OpacityImage out;
  if (material.opacity_texture.empty()) return out;
  Image texels = load_texture(material.opacity_texture);
  bool opaque_alpha = true;
  for (std::size_t i = 3; i < texels.rgba.size(); i += 4) opaque_alpha = opaque_alpha && texels.rgba[i] == 255;
  out.width = texels.width;
  out.height = texels.height;
  out.values.resize(texels.rgba.size() / 4);
  for (std::size_t i = 0; i < out.values.size(); ++i) out.values[i] = texels.rgba[4 * i + (opaque_alpha ? 0 : 3)];
  return out;
}

namespace {

// Value noise on an integer lattice (hashed), smoothstep-interpolated.
float lattice(std::uint32_t seed, int x, int y) {
  std::uint32_t h = seed * 0x9e3779b9u ^ std::uint32_t(x) * 0x85ebca6bu ^ std::uint32_t(y) * 0xc2b2ae35u;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return float(h & 0xffffffu) / float(0xffffff);
}

float value_noise(std::uint32_t seed, float x, float y) {
  int i = int(std::floor(x)), j = int(std::floor(y));
  float fx = x - float(i), fy = y - float(j);
  float sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
  float a = lattice(seed, i, j), b = lattice(seed, i + 1, j), c = lattice(seed, i, j + 1),
        d = lattice(seed, i + 1, j + 1);
  return (1 - sy) * ((1 - sx) * a + sx * b) + sy * ((1 - sx) * c + sx * d);
}

} // namespace

OpacityImage make_smoke_opacity(const SmokeNoise& n) {
  const int size = 128;
  OpacityImage out;
  out.width = out.height = size;
  out.values.resize(std::size_t(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float u = (float(x) + 0.5f) / size, v = (float(y) + 0.5f) / size;
      float f = 0, amplitude = 0.5f, total = 0, frequency = n.scale;
      for (int o = 0; o < n.octaves; ++o) {
        f += amplitude * value_noise(n.seed + std::uint32_t(o) * 7919u, u * frequency, v * frequency);
        total += amplitude;
        amplitude *= 0.5f;
        frequency *= 2.0f;
      }
      f /= total;
      // A soft disc: full inside radius 0.25, fading to zero at 0.5 (the sprite's edge).
      float r = std::hypot(u - 0.5f, v - 0.5f);
      float disc = std::clamp((0.5f - r) / 0.25f, 0.0f, 1.0f);
      float puff = std::clamp((f - n.density) / n.softness + 0.5f, 0.0f, 1.0f) * disc;
      out.values[std::size_t(y) * size + std::size_t(x)] = std::uint8_t(std::lround(255.0f * puff));
    }
  return out;
}

} // namespace msm::scene
