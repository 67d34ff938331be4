// Mesh import through Assimp, and minimal texture loading through stb_image.
#include <system_error>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#define STB_IMAGE_STATIC  // private copy: no clash with a libstb linked by the application
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

}  // namespace

Mesh import_mesh(const std::filesystem::path& file) {
  check_regular_file(file, "mesh");
  Assimp::Importer importer;
  // Points and lines are removed; only triangles are kept.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_PreTransformVertices | aiProcess_GenSmoothNormals |
                         aiProcess_SortByPType | aiProcess_ValidateDataStructure;
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
  } catch (const SceneError& e) {
    throw SceneError(file.string(), "", e.problem());
  }
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

}  // namespace msm::scene
