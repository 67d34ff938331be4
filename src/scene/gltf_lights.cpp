// KHR_lights_punctual: the lights of a glTF 2.0 file, read from its JSON (a .gltf file, or a .glb's
// JSON chunk) without Assimp, placed by the node hierarchy.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "internal.h"

namespace msm::scene::detail {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& problem) { throw SceneError("", "", problem); }

// The JSON text of a .gltf file, or of a .glb's first chunk (glTF 2.0 §4.4: a 12-byte header,
// then chunks of length, type and data; the first is the JSON).
std::string gltf_json_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail("cannot read the file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 4 || bytes.compare(0, 4, "glTF") != 0) return bytes;
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20) fail("a .glb shorter than its header");
  const std::uint32_t length = u32(12), type = u32(16);
  if (type != 0x4E4F534Au) fail("a .glb whose first chunk is not its JSON");
  if (length > bytes.size() - 20) fail("a .glb whose JSON chunk runs past the end of the file");
  return bytes.substr(20, length);
}

float number(const json& j, const char* key, float fallback) {
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  if (!it->is_number() || !std::isfinite(it->get<double>())) fail(fmt::format("\"{}\" must be a finite number", key));
  return it->get<float>();
}

glm::vec3 vec3_of(const json& j, const char* key, glm::vec3 fallback) {
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  if (!it->is_array() || it->size() != 3) fail(fmt::format("\"{}\" must be an array of 3 numbers", key));
  glm::vec3 v;
  for (int i = 0; i < 3; ++i) {
    if (!(*it)[i].is_number()) fail(fmt::format("\"{}\" must be an array of 3 numbers", key));
    v[i] = (*it)[i].get<float>();
  }
  return v;
}

// A node's local matrix (glTF 2.0 §3.5.3): "matrix" (column-major), else T R S.
glm::mat4 local_matrix(const json& node) {
  if (const auto m = node.find("matrix"); m != node.end()) {
    if (!m->is_array() || m->size() != 16) fail("a node's \"matrix\" must be an array of 16 numbers");
    glm::mat4 r;
    for (int i = 0; i < 16; ++i) {
      if (!(*m)[i].is_number()) fail("a node's \"matrix\" must be an array of 16 numbers");
      glm::value_ptr(r)[i] = (*m)[i].get<float>();
    }
    return r;
  }
  glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
  if (const auto r = node.find("rotation"); r != node.end()) {
    if (!r->is_array() || r->size() != 4) fail("a node's \"rotation\" must be a quaternion [x, y, z, w]");
    q = glm::quat((*r)[3].get<float>(), (*r)[0].get<float>(), (*r)[1].get<float>(), (*r)[2].get<float>());
  }
  const glm::vec3 t = vec3_of(node, "translation", glm::vec3(0.0f)), s = vec3_of(node, "scale", glm::vec3(1.0f));
  glm::mat4 m(1.0f);
  m[3] = glm::vec4(t, 1.0f);
  return m * glm::mat4_cast(glm::normalize(q)) * glm::mat4(glm::mat3(s.x, 0, 0, 0, s.y, 0, 0, 0, s.z));
}

std::vector<FileLight> lights_of(const json& root);

} // namespace

std::vector<FileLight> gltf_lights(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext != ".gltf" && ext != ".glb" && ext != ".GLTF" && ext != ".GLB")
    fail("imports the KHR_lights_punctual lights of glTF files (.gltf, .glb) only");
  json root;
  try {
    root = json::parse(gltf_json_text(file));
  } catch (const json::exception& e) { fail(fmt::format("malformed glTF JSON: {}", e.what())); }
  try {
    return lights_of(root);
  } catch (const json::exception& e) { fail(fmt::format("a glTF value of the wrong type: {}", e.what())); }
}

namespace {

std::vector<FileLight> lights_of(const json& root) {
  std::vector<FileLight> out;
  const json* defs = nullptr;
  if (const auto e = root.find("extensions"); e != root.end() && e->is_object())
    if (const auto k = e->find("KHR_lights_punctual"); k != e->end() && k->is_object())
      if (const auto l = k->find("lights"); l != k->end() && l->is_array()) defs = &*l;
  if (!defs) return out;
  const json nodes = root.value("nodes", json::array());
  if (!nodes.is_array()) fail("\"nodes\" must be an array");
  // The roots: the file's scene (its "scene", else the first), or without scenes every node that
  // is no node's child.
  std::vector<std::size_t> roots;
  const json scenes = root.value("scenes", json::array());
  if (scenes.is_array() && !scenes.empty()) {
    const std::size_t index = root.value("scene", std::size_t(0));
    if (index >= scenes.size()) fail(fmt::format("\"scene\" {} is not one of its {} scenes", index, scenes.size()));
    for (const json& n : scenes[index].value("nodes", json::array())) roots.push_back(n.get<std::size_t>());
  } else {
    std::vector<bool> child(nodes.size(), false);
    for (const json& n : nodes)
      for (const json& c : n.value("children", json::array()))
        if (c.get<std::size_t>() < child.size()) child[c.get<std::size_t>()] = true;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (!child[i]) roots.push_back(i);
  }
  // Depth first; a node met twice (a cycle, or a node under two parents) is an error.
  std::vector<bool> visited(nodes.size(), false);
  std::vector<std::pair<std::size_t, glm::mat4>> stack;
  for (std::size_t r : roots) stack.emplace_back(r, glm::mat4(1.0f));
  while (!stack.empty()) {
    const auto [index, parent] = stack.back();
    stack.pop_back();
    if (index >= nodes.size()) fail(fmt::format("node {} does not exist ({} nodes)", index, nodes.size()));
    if (visited[index]) fail(fmt::format("node {} is reached twice (a cycle, or two parents)", index));
    visited[index] = true;
    const json& node = nodes[index];
    const glm::mat4 world = parent * local_matrix(node);
    for (const json& c : node.value("children", json::array())) stack.emplace_back(c.get<std::size_t>(), world);
    const auto ext_it = node.find("extensions");
    if (ext_it == node.end() || !ext_it->contains("KHR_lights_punctual")) continue;
    const std::size_t light = (*ext_it)["KHR_lights_punctual"].value("light", defs->size());
    if (light >= defs->size()) fail(fmt::format("node {} names light {} of {}", index, light, defs->size()));
    const json& def = (*defs)[light];
    FileLight f;
    f.index = light;
    f.name = def.value("name", std::string());
    const std::string type = def.value("type", std::string());
    if (type == "directional")
      f.kind = LightKind::directional;
    else if (type == "spot")
      f.kind = LightKind::spot;
    else if (type == "point")
      f.kind = LightKind::point;
    else
      fail(fmt::format("light {} has the type '{}' (directional, spot or point)", light, type));
    f.intensity = vec3_of(def, "color", glm::vec3(1.0f)) * number(def, "intensity", 1.0f);
    if (def.contains("range")) f.range = number(def, "range", 0.0f);
    if (f.kind == LightKind::spot) {
      const json spot = def.value("spot", json::object());
      const float to_deg = float(180.0 / std::numbers::pi);
      f.inner_cone_deg = number(spot, "innerConeAngle", 0.0f) * to_deg;
      f.outer_cone_deg = number(spot, "outerConeAngle", float(std::numbers::pi / 4.0)) * to_deg;
    }
    // The light shines along the node's -Z from its origin.
    f.position = glm::vec3(world[3]);
    f.direction = -glm::vec3(world[2]);
    out.push_back(f);
  }
  return out;
}

} // namespace
} // namespace msm::scene::detail
