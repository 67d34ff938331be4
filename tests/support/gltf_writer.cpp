// Test support: a minimal glTF 2.0 writer (see msm/test/gltf_writer.h).
#include "msm/test/gltf_writer.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace msm::scene::testing {
namespace {

using nlohmann::json;

std::string base64(const std::vector<std::uint8_t>& data) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 3) {
    const std::uint32_t n = (std::uint32_t(data[i]) << 16) | (i + 1 < data.size() ? data[i + 1] << 8 : 0) |
                            (i + 2 < data.size() ? data[i + 2] : 0);
    out += k[(n >> 18) & 63];
    out += k[(n >> 12) & 63];
    out += i + 1 < data.size() ? k[(n >> 6) & 63] : '=';
    out += i + 2 < data.size() ? k[n & 63] : '=';
  }
  return out;
}

std::vector<std::uint8_t> png(const GltfTexture& t) {
  std::vector<std::uint8_t> out;
  stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        auto* v = static_cast<std::vector<std::uint8_t>*>(context);
        v->insert(v->end(), static_cast<std::uint8_t*>(data), static_cast<std::uint8_t*>(data) + size);
      },
      &out, t.width, t.height, 4, t.rgba.data(), t.width * 4);
  if (out.empty()) throw std::runtime_error("gltf_writer: PNG encoding failed");
  return out;
}

// The one buffer, with a buffer view per appended block (4-byte aligned).
struct Buffer {
  std::vector<std::uint8_t> bytes;
  json views = json::array();
  int add(const void* data, std::size_t size, int target) {
    while (bytes.size() % 4) bytes.push_back(0);
    json view = {{"buffer", 0}, {"byteOffset", bytes.size()}, {"byteLength", size}};
    if (target) view["target"] = target;
    bytes.insert(bytes.end(), static_cast<const std::uint8_t*>(data), static_cast<const std::uint8_t*>(data) + size);
    views.push_back(view);
    return int(views.size()) - 1;
  }
};

void write_bytes(const std::filesystem::path& file, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(file, std::ios::binary);
  if (!out || !out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size())))
    throw std::runtime_error("gltf_writer: cannot write " + file.string());
}

} // namespace

GltfPrimitive quad(glm::vec3 origin, glm::vec3 u, glm::vec3 v, glm::vec3 normal, int material) {
  GltfPrimitive p;
  p.material = material;
  const glm::vec2 st[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const glm::vec2& c : st) {
    p.positions.push_back(origin + c.x * u + c.y * v);
    p.normals.push_back(glm::normalize(normal));
    p.uvs.push_back(c);
  }
  p.indices = glm::dot(glm::cross(u, v), normal) > 0.0f ? std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}
                                                        : std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2};
  return p;
}

GltfModel alpha_modes_model(const GltfTexture& texture) {
  GltfModel model;
  model.textures = {texture};
  model.materials = {{.name = "mask",
                      .base_color = {1, 1, 1, 0.9f},
                      .texture = 0,
                      .alpha_mode = "MASK",
                      .alpha_cutoff = 0.3f,
                      .double_sided = true},
                     {.name = "blend", .base_color = {1, 1, 1, 0.5f}, .alpha_mode = "BLEND"},
                     {.name = "opaque", .base_color = {0.5f, 0.5f, 0.5f, 0.2f}, .texture = 0},
                     {.name = "glass", .base_color = {1, 0.5f, 0.25f, 1}, .transmission = 0.8f}};
  for (int i = 0; i < 4; ++i) model.primitives.push_back(quad({2.0f * i, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, 1, 0}, i));
  return model;
}

void write_gltf(const std::filesystem::path& file, const GltfModel& model, bool external_pictures) {
  const bool glb = file.extension() == ".glb";
  Buffer buffer;
  json accessors = json::array(), primitives = json::array();
  auto accessor = [&](int view, int component, std::size_t count, const char* type, json extra = json::object()) {
    json a = {{"bufferView", view}, {"componentType", component}, {"count", count}, {"type", type}};
    a.update(extra);
    accessors.push_back(a);
    return int(accessors.size()) - 1;
  };
  for (const GltfPrimitive& p : model.primitives) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& q : p.positions) {
      lo = glm::min(lo, q);
      hi = glm::max(hi, q);
    }
    json attributes;
    attributes["POSITION"] =
        accessor(buffer.add(p.positions.data(), p.positions.size() * 12, 34962), 5126, p.positions.size(), "VEC3",
                 {{"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}});
    if (!p.normals.empty())
      attributes["NORMAL"] =
          accessor(buffer.add(p.normals.data(), p.normals.size() * 12, 34962), 5126, p.normals.size(), "VEC3");
    if (!p.uvs.empty())
      attributes["TEXCOORD_0"] =
          accessor(buffer.add(p.uvs.data(), p.uvs.size() * 8, 34962), 5126, p.uvs.size(), "VEC2");
    json prim = {{"attributes", attributes},
                 {"indices", accessor(buffer.add(p.indices.data(), p.indices.size() * 4, 34963), 5125, p.indices.size(),
                                      "SCALAR")}};
    if (p.material >= 0) prim["material"] = p.material;
    if (p.mode != 4) prim["mode"] = p.mode;
    primitives.push_back(prim);
  }
  json images = json::array(), textures = json::array();
  for (std::size_t i = 0; i < model.textures.size(); ++i) {
    const std::vector<std::uint8_t> bytes = png(model.textures[i]);
    if (glb) {
      images.push_back({{"bufferView", buffer.add(bytes.data(), bytes.size(), 0)}, {"mimeType", "image/png"}});
    } else if (external_pictures) {
      const std::string name = file.stem().string() + "_" + std::to_string(i) + ".png";
      write_bytes(file.parent_path() / name, bytes);
      images.push_back({{"uri", name}});
    } else {
      images.push_back({{"uri", "data:image/png;base64," + base64(bytes)}});
    }
    textures.push_back({{"source", i}, {"sampler", 0}});
  }
  json materials = json::array();
  std::vector<std::string> used;
  for (const GltfMaterial& m : model.materials) {
    json pbr = {{"baseColorFactor", {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a}},
                {"metallicFactor", 0.0}};
    if (m.texture >= 0) pbr["baseColorTexture"] = {{"index", m.texture}};
    if (m.texture >= 0 && (m.uv_offset != glm::vec2(0.0f) || m.uv_scale != glm::vec2(1.0f) || m.uv_rotation != 0.0f)) {
      pbr["baseColorTexture"]["extensions"] = {{"KHR_texture_transform",
                                                {{"offset", {m.uv_offset.x, m.uv_offset.y}},
                                                 {"scale", {m.uv_scale.x, m.uv_scale.y}},
                                                 {"rotation", m.uv_rotation}}}};
      used.push_back("KHR_texture_transform");
    }
    json mat = {{"pbrMetallicRoughness", pbr}, {"alphaMode", m.alpha_mode}, {"doubleSided", m.double_sided}};
    if (!m.name.empty()) mat["name"] = m.name;
    if (m.alpha_mode == "MASK") mat["alphaCutoff"] = m.alpha_cutoff;
    if (m.transmission > 0.0f) {
      mat["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", m.transmission}}}};
      used.push_back("KHR_materials_transmission");
    }
    materials.push_back(mat);
  }
  while (buffer.bytes.size() % 4) buffer.bytes.push_back(0);
  json root = {
      {"asset", {{"version", "2.0"}, {"generator", "msm gltf_writer"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}, {"translation", {model.translation.x, model.translation.y, model.translation.z}}}}},
      {"meshes", {{{"primitives", primitives}}}},
      {"accessors", accessors},
      {"bufferViews", buffer.views}};
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  if (!used.empty()) root["extensionsUsed"] = used;
  if (!materials.empty()) root["materials"] = materials;
  if (!images.empty()) {
    root["images"] = images;
    root["textures"] = textures;
    // Nearest filtering would differ from msm's linear sampler only between texel centres.
    root["samplers"] = {{{"magFilter", 9729}, {"minFilter", 9729}, {"wrapS", 10497}, {"wrapT", 10497}}};
  }
  if (glb) {
    root["buffers"] = {{{"byteLength", buffer.bytes.size()}}};
    std::string text = root.dump();
    while (text.size() % 4) text += ' ';
    std::vector<std::uint8_t> out;
    auto u32 = [&](std::uint32_t v) {
      for (int k = 0; k < 4; ++k) out.push_back(std::uint8_t(v >> (8 * k)));
    };
    u32(0x46546C67u); // "glTF"
    u32(2);
    u32(std::uint32_t(12 + 8 + text.size() + 8 + buffer.bytes.size()));
    u32(std::uint32_t(text.size()));
    u32(0x4E4F534Au); // JSON
    out.insert(out.end(), text.begin(), text.end());
    u32(std::uint32_t(buffer.bytes.size()));
    u32(0x004E4942u); // BIN
    out.insert(out.end(), buffer.bytes.begin(), buffer.bytes.end());
    write_bytes(file, out);
    return;
  }
  root["buffers"] = {
      {{"byteLength", buffer.bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(buffer.bytes)}}};
  const std::string text = root.dump(1);
  write_bytes(file, std::vector<std::uint8_t>(text.begin(), text.end()));
}

} // namespace msm::scene::testing
