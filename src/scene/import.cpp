// Mesh import through Assimp, and minimal texture loading through stb_image.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <assimp/GltfMaterial.h>
#include <assimp/Importer.hpp>
#include <assimp/material.h>
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

namespace {

// Why stb could not decode a texture's bytes, naming the format where it is a known one stb lacks
// (glTF's KHR_texture_basisu brings KTX2, KHR_texture_webp WebP).
std::string undecodable_texture(std::span<const unsigned char> bytes) {
  const auto starts = [&](std::string_view magic, std::size_t at = 0) {
    return bytes.size() >= at + magic.size() &&
           std::equal(magic.begin(), magic.end(), bytes.begin() + std::ptrdiff_t(at),
                      [](char a, unsigned char b) { return static_cast<unsigned char>(a) == b; });
  };
  constexpr std::string_view readable = "PNG, JPEG, TGA, BMP, GIF, HDR, PSD or PNM";
  std::string_view format;
  if (bytes.empty()) return "the image is empty (0 bytes)";
  if (starts("\xABKTX 20\xBB\r\n\x1A\n"))
    format = "KTX2";
  else if (starts("\xABKTX 11\xBB\r\n\x1A\n"))
    format = "KTX";
  else if (starts("DDS "))
    format = "DDS";
  else if (starts("RIFF") && starts("WEBP", 8))
    format = "WebP";
  else if (starts("\x89PNG"))
    return fmt::format("a PNG that cannot be decoded: {}", stbi_failure_reason());
  if (!format.empty()) return fmt::format("a {} image, which msm does not read ({} are read)", format, readable);
  return fmt::format("not an image msm reads ({}): {}", readable, stbi_failure_reason());
}

Image decoded_rgba(stbi_uc* data, int w, int h) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(data, data + std::size_t(w) * h * 4);
  stbi_image_free(data);
  return img;
}

// Texels of a texture embedded in the file (its index in the file): compressed (PNG, JPEG:
// mHeight 0, mWidth bytes) or raw BGRA8.
Image decode_embedded(const aiTexture& t, int index, const std::filesystem::path& file) {
  Image img;
  if (t.mHeight == 0) {
    const std::span<const unsigned char> bytes(reinterpret_cast<const unsigned char*>(t.pcData), t.mWidth);
    int w = 0, h = 0, channels = 0;
    stbi_uc* data = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels, 4);
    if (!data) {
      const std::string name = t.mFilename.length > 0 ? fmt::format(" '{}'", t.mFilename.C_Str()) : "";
      const std::string hint = t.achFormatHint[0] ? fmt::format(", format hint '{:.4}'", t.achFormatHint) : "";
      throw SceneError(
          file.string(), "",
          fmt::format("cannot decode embedded texture {}{}{}: {}", index, name, hint, undecodable_texture(bytes)));
    }
    return decoded_rgba(data, w, h);
  }
  img.width = int(t.mWidth);
  img.height = int(t.mHeight);
  img.rgba.resize(std::size_t(t.mWidth) * t.mHeight * 4);
  for (std::size_t i = 0; i < std::size_t(t.mWidth) * t.mHeight; ++i) {
    const aiTexel& texel = t.pcData[i];
    img.rgba[4 * i + 0] = texel.r;
    img.rgba[4 * i + 1] = texel.g;
    img.rgba[4 * i + 2] = texel.b;
    img.rgba[4 * i + 3] = texel.a;
  }
  return img;
}

struct TextureRef {
  std::filesystem::path path;
  std::shared_ptr<const Image> pixels; // embedded ones
};

// The first texture of a type: embedded (decoded, once per index), or a file next to the model.
std::optional<TextureRef> texture_of(const aiScene& s, const aiMaterial& m, aiTextureType type,
                                     const std::filesystem::path& file,
                                     std::map<int, std::shared_ptr<const Image>>& decoded) {
  aiString name;
  if (m.GetTextureCount(type) == 0 || m.GetTexture(type, 0, &name) != AI_SUCCESS || name.length == 0)
    return std::nullopt;
  const auto [embedded, index] = s.GetEmbeddedTextureAndIndex(name.C_Str());
  if (embedded) {
    auto& pixels = decoded[index];
    if (!pixels) pixels = std::make_shared<const Image>(decode_embedded(*embedded, index, file));
    return TextureRef{std::filesystem::path(file.string() + "#" + std::to_string(index)), pixels};
  }
  const std::filesystem::path path = (file.parent_path() / std::filesystem::path(name.C_Str())).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw SceneError(file.string(), "",
                     fmt::format("texture file '{}' does not exist or is not a file", path.string()));
  return TextureRef{path, nullptr};
}

float clamp01(float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 1.0f; }

// What msm reads of a material (scenes/README.md): glTF's metallic-roughness base colour, alpha
// mode and cutoff, double-sidedness and transmission factor; the diffuse colour, texture and
// opacity of the other formats.
Material convert_material(const aiScene& s, const aiMaterial& m, const std::filesystem::path& file,
                          std::map<int, std::shared_ptr<const Image>>& decoded) {
  Material out;
  aiString name;
  if (m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) out.name = name.C_Str();
  aiString alpha_mode;
  const bool gltf = m.Get(AI_MATKEY_GLTF_ALPHAMODE, alpha_mode) == AI_SUCCESS;
  aiColor4D colour(0.8f, 0.8f, 0.8f, 1.0f);
  if (m.Get(AI_MATKEY_BASE_COLOR, colour) != AI_SUCCESS) {
    aiColor4D diffuse;
    if (m.Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == AI_SUCCESS)
      colour = aiColor4D(diffuse.r, diffuse.g, diffuse.b, 1.0f);
    float opacity = 1.0f;
    if (m.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) colour.a = opacity;
  }
  out.albedo = glm::vec3(clamp01(colour.r), clamp01(colour.g), clamp01(colour.b));
  std::optional<TextureRef> texture = texture_of(s, m, aiTextureType_BASE_COLOR, file, decoded);
  if (!texture) texture = texture_of(s, m, aiTextureType_DIFFUSE, file, decoded);
  if (texture) {
    out.albedo_texture = texture->path;
    out.albedo_pixels = texture->pixels;
  }
  int two_sided = 0;
  if (m.Get(AI_MATKEY_TWOSIDED, two_sided) == AI_SUCCESS) out.double_sided = two_sided != 0;
  const std::string mode = gltf ? alpha_mode.C_Str() : (colour.a < 1.0f ? "BLEND" : "OPAQUE");
  if (mode == "MASK" || mode == "BLEND") {
    out.opacity = clamp01(colour.a);
    if (gltf && texture) { // the base colour's alpha
      out.opacity_texture = texture->path;
      out.opacity_pixels = texture->pixels;
      out.opacity_from_alpha = true;
    }
    if (mode == "MASK") {
      float cutoff = 0.5f; // glTF's default
      m.Get(AI_MATKEY_GLTF_ALPHACUTOFF, cutoff);
      out.alpha_cutoff = clamp01(cutoff);
    }
  }
  // KHR_materials_transmission: that fraction of the light passes, tinted by the base colour.
  float transmission = 0.0f;
  if (m.Get(AI_MATKEY_TRANSMISSION_FACTOR, transmission) == AI_SUCCESS && transmission > 0.0f && !out.masked())
    out.transmission_color = clamp01(transmission) * out.albedo;
  return out;
}

// KHR_texture_transform of a glTF material's base colour texture, as the matrix its specification
// applies to texture coordinates: translation * rotation * scale. Assimp 5.2 hands the extension
// out converted to its v-up convention (aiUVTransform: rotation negated, translation moved so that
// it rotates about the centre, v flipped; FlipUVs then negates rotation and translation.y again);
// that is undone here, because Assimp's own TransformUVCoords step puts v off by up to the scale
// where there is a rotation. Identity for other formats (their UV transforms are not read) and
// without the extension.
glm::mat3 gltf_texture_transform(const aiMaterial& m) {
  aiString alpha_mode;
  aiUVTransform t;
  if (m.Get(AI_MATKEY_GLTF_ALPHAMODE, alpha_mode) != AI_SUCCESS) return glm::mat3(1.0f);
  if (m.Get(AI_MATKEY_UVTRANSFORM(aiTextureType_BASE_COLOR, 0), t) != AI_SUCCESS &&
      m.Get(AI_MATKEY_UVTRANSFORM(aiTextureType_DIFFUSE, 0), t) != AI_SUCCESS)
    return glm::mat3(1.0f);
  const double rotation = double(t.mRotation), c = std::cos(rotation), s = std::sin(rotation);
  const glm::dvec2 scale(t.mScaling.x, t.mScaling.y);
  const glm::dvec2 offset(double(t.mTranslation.x) - 0.5 * scale.x * (1.0 - c + s),
                          1.0 - scale.y + 0.5 * scale.y * (s + c - 1.0) + double(t.mTranslation.y));
  // Columns (cos, -sin) scale.x, (sin, cos) scale.y, offset: u turns away from v, so that the
  // Khronos TextureTransformTest sample's arrows point at their "correct" marks (the draft text of
  // the extension printed the other sign).
  return glm::mat3(glm::vec3(float(c * scale.x), float(-s * scale.x), 0.0f),
                   glm::vec3(float(s * scale.y), float(c * scale.y), 0.0f),
                   glm::vec3(float(offset.x), float(offset.y), 1.0f));
}

bool same_material(const std::optional<Material>& a, const std::optional<Material>& b) {
  if (!a || !b) return !a && !b;
  return a->albedo == b->albedo && a->albedo_texture == b->albedo_texture && a->opacity == b->opacity &&
         a->opacity_texture == b->opacity_texture && a->opacity_from_alpha == b->opacity_from_alpha &&
         a->alpha_cutoff == b->alpha_cutoff && a->double_sided == b->double_sided &&
         a->transmission_color == b->transmission_color;
}

} // namespace

// Debian's Assimp is built with ASSIMP_BUILD_DEBUG: an internal assertion (a truncated PLY trips
// one in TriangulateProcess) prints and aborts the process, and this version has no handler to
// install. The definition of Assimp::aiAssertViolation below interposes the library's (ELF symbol
// interposition: the executable's definition wins over the shared library's exported one): the
// assertion becomes an exception, which Importer::ReadFile swallows (or we catch), and the import
// fails with a SceneError naming the file.
namespace {
thread_local std::string assimp_assertion; // the last assertion of this thread's import
} // namespace
} // namespace msm::scene

namespace Assimp {
void aiAssertViolation(const char* expression, const char* file, int line) {
  msm::scene::assimp_assertion = fmt::format("{} ({}:{})", expression, file, line);
  throw std::runtime_error("Assimp's internal check failed: " + msm::scene::assimp_assertion);
}
} // namespace Assimp

namespace msm::scene {

// Assimp and the conversion to parts, in this process: the child's half of import_model
// (import_child.cpp), after the parent's checks of the file and its header.
std::vector<ModelPart> detail::import_model_in_process(const std::filesystem::path& file) {
  Assimp::Importer importer;
  // Points and lines are skipped below, not removed by Assimp (AI_CONFIG_PP_SBP_REMOVE): a file of
  // nothing else would end in Assimp's "No meshes remaining" instead of saying what it holds.
  // FlipUVs: Assimp hands out v up (OpenGL), msm and Vulkan sample with v down (row 0 on top).
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                         aiProcess_GenSmoothNormals | aiProcess_SortByPType | aiProcess_ValidateDataStructure |
                         aiProcess_FlipUVs;
  assimp_assertion.clear();
  const aiScene* s = nullptr;
  try {
    s = importer.ReadFile(file.string(), flags);
  } catch (const std::exception&) {
    s = nullptr; // an assertion (above) that ReadFile let through
  }
  if (!assimp_assertion.empty())
    throw SceneError(file.string(), "",
                     fmt::format("Assimp cannot read the mesh (truncated or corrupt?): its internal check {} failed",
                                 assimp_assertion));
  // Assimp catches std::bad_alloc (the child's address-space limit, import_child.cpp) and keeps
  // only its what(): it is raised again, for the caller's message naming the memory limit.
  if (!s && std::string_view(importer.GetErrorString()).find("bad_alloc") != std::string_view::npos)
    throw std::bad_alloc();
  if (!s || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !s->mRootNode)
    throw SceneError(file.string(), "", fmt::format("Assimp cannot read the mesh: {}", importer.GetErrorString()));
  // One part per distinct material: Assimp repeats a glTF material for every mesh that uses it.
  std::map<unsigned, std::size_t> part_of_material;
  std::vector<ModelPart> parts;
  std::map<int, std::shared_ptr<const Image>> decoded;
  bool points_or_lines = false;
  for (unsigned mi = 0; mi < s->mNumMeshes; ++mi) {
    const aiMesh* am = s->mMeshes[mi];
    points_or_lines |= (am->mPrimitiveTypes & (aiPrimitiveType_POINT | aiPrimitiveType_LINE)) != 0;
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || !am->mVertices) continue;
    auto [it, inserted] = part_of_material.try_emplace(am->mMaterialIndex, parts.size());
    if (inserted) {
      ModelPart part;
      part.name = fmt::format("part{}", parts.size());
      if (am->mMaterialIndex < s->mNumMaterials) {
        const aiMaterial& material = *s->mMaterials[am->mMaterialIndex];
        aiString name;
        material.Get(AI_MATKEY_NAME, name);
        // Formats without materials get one from Assimp, named AI_DEFAULT_MATERIAL_NAME or unnamed
        // (OFF, PLY): those parts keep the scene's default material.
        if (name.length > 0) part.name = name.C_Str();
        if (name.length > 0 && part.name != AI_DEFAULT_MATERIAL_NAME)
          part.material = convert_material(*s, material, file, decoded);
      }
      const auto same = std::find_if(parts.begin(), parts.end(), [&](const ModelPart& p) {
        return p.name == part.name && same_material(p.material, part.material);
      });
      if (same != parts.end())
        it->second = std::size_t(same - parts.begin());
      else
        parts.push_back(std::move(part));
    }
    const glm::mat3 uv_matrix = am->mMaterialIndex < s->mNumMaterials
                                    ? gltf_texture_transform(*s->mMaterials[am->mMaterialIndex])
                                    : glm::mat3(1.0f);
    Mesh& m = parts[it->second].mesh;
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      m.positions.emplace_back(p.x, p.y, p.z);
      m.normals.push_back(am->mNormals ? glm::vec3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z)
                                       : glm::vec3(0.0f));
      m.uvs.push_back(am->mTextureCoords[0] ? glm::vec2(uv_matrix * glm::vec3(am->mTextureCoords[0][v].x,
                                                                              am->mTextureCoords[0][v].y, 1.0f))
                                            : glm::vec2(0.0f));
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) m.indices.push_back(base + face.mIndices[k]);
    }
  }
  // Parts whose triangles are all degenerate are dropped; a file without any is an error.
  std::vector<ModelPart> kept;
  for (ModelPart& part : parts) {
    if (part.mesh.indices.empty()) continue;
    try {
      detail::finalize_mesh(part.mesh, "");
    } catch (const SceneError& e) {
      if (e.problem().find("no triangles with a non-zero area") != std::string::npos) continue;
      throw SceneError(file.string(), "", e.problem());
    }
    kept.push_back(std::move(part));
  }
  if (parts.empty())
    throw SceneError(file.string(), "",
                     points_or_lines ? "the mesh file contains no triangles, only points or lines (msm draws triangles)"
                                     : "the mesh file contains no triangles");
  if (kept.empty()) throw SceneError(file.string(), "", "the mesh has no triangles with a non-zero area");
  return kept;
}

void detail::check_mesh_file(const std::filesystem::path& file) {
  check_regular_file(file, "mesh");
  check_mesh_header(file);
}

Mesh import_mesh(const std::filesystem::path& file) {
  Mesh m;
  for (const ModelPart& part : import_model(file)) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), part.mesh.positions.begin(), part.mesh.positions.end());
    m.normals.insert(m.normals.end(), part.mesh.normals.begin(), part.mesh.normals.end());
    m.uvs.insert(m.uvs.end(), part.mesh.uvs.begin(), part.mesh.uvs.end());
    for (std::uint32_t i : part.mesh.indices) m.indices.push_back(base + i);
  }
  return m;
}

Image load_texture(const std::filesystem::path& file) {
  check_regular_file(file, "texture");
  std::ifstream in(file, std::ios::binary);
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.eof() && in.fail()) throw SceneError(file.string(), "", "cannot read the texture file");
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels, 4);
  if (!data)
    throw SceneError(file.string(), "", fmt::format("cannot decode the texture: {}", undecodable_texture(bytes)));
  return decoded_rgba(data, w, h);
}

} // namespace msm::scene

namespace msm::scene {

float OpacityImage::sample(glm::vec2 uv) const {
  if (width == 0) return 1.0f;
  return sample_bilinear_repeat<float>(width, height, uv, [&](int i, int j) {
    return float(values[std::size_t(j) * std::size_t(width) + std::size_t(i)]) / 255.0f;
  });
}

Image albedo_image(const Material& material) {
  if (material.albedo_pixels) return *material.albedo_pixels;
  if (material.albedo_texture.empty()) return {};
  return load_texture(material.albedo_texture);
}

OpacityImage opacity_image(const Material& material) {
  if (material.opacity_noise) return make_smoke_opacity(*material.opacity_noise);
  OpacityImage out;
  if (material.opacity_texture.empty()) return out;
  const Image texels = material.opacity_pixels ? *material.opacity_pixels : load_texture(material.opacity_texture);
  bool opaque_alpha = !material.opacity_from_alpha;
  for (std::size_t i = 3; opaque_alpha && i < texels.rgba.size(); i += 4) opaque_alpha = texels.rgba[i] == 255;
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
