#include "gpu_scene.h"

#include "msm/probe/probe.h"

#include <algorithm>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

namespace msm::render {
namespace {

// A sampled texture of 8-bit texels: rgba (R8G8B8A8_SRGB) or opacity (R8_UNORM).
vk::Image upload_texture(const vk::Context& ctx, VkFormat format, int width, int height,
                         std::span<const std::uint8_t> texels) {
  vk::Image image = vk::create_image(ctx, {.width = uint32_t(width),
                                           .height = uint32_t(height),
                                           .format = format,
                                           .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
  vk::upload_image(ctx, image, std::as_bytes(texels), VK_IMAGE_LAYOUT_UNDEFINED,
                   VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  return image;
}

// The vertices and indices of every object in scene order; a translucent object's triangles far
// to near along the light's travel. first_index: each object's first index.
struct Geometry {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices, first_index;
};

// "directional and ..." lights: the kinds the renderer draws.
std::string rendered_light_kinds() {
  std::vector<std::string_view> names;
  for (const scene::LightKindInfo& kind : scene::light_kinds())
    if (kind.rendered) names.push_back(kind.name);
  return fmt::format("{} lights only", fmt::join(names, " and "));
}

// How far from the light a point lies, along which translucent surfaces are sorted far to near
// (JCGT §3) for the renderer's first shadow-map layer: along the first directional light's
// travel, or in a scene of spot and point lights only by the distance from the first spot light
// (else the first point light), whose layer comes first. The translucent pass re-sorts the objects
// for its other layers; each object's triangles keep this order.
struct LightFarness {
  bool local = false;
  glm::vec3 travel{0.0f, -1.0f, 0.0f}, position{0.0f};
  float operator()(glm::vec3 p) const { return local ? glm::distance(p, position) : glm::dot(p, travel); }
};

LightFarness translucent_farness(const scene::Scene& scene) {
  if (!scene.lights.empty()) return {.travel = scene.light().travel()};
  auto spot = std::ranges::find_if(scene.local_lights, &scene::LocalLight::spot);
  if (spot != scene.local_lights.end()) return {.local = true, .position = spot->position};
  if (!scene.local_lights.empty()) return {.local = true, .position = scene.local_lights.front().position};
  return {};
}

Geometry geometry(const scene::Scene& scene) {
  Geometry g;
  const LightFarness farness = translucent_farness(scene);
  for (const scene::Object& object : scene.objects) {
    const scene::Mesh& mesh = object.mesh;
    const uint32_t base = uint32_t(g.vertices.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
      g.vertices.push_back({mesh.positions[i], mesh.normals[i], i < mesh.uvs.size() ? mesh.uvs[i] : glm::vec2(0.0f)});
    g.first_index.push_back(uint32_t(g.indices.size()));
    std::vector<uint32_t> triangles(mesh.triangle_count());
    for (uint32_t t = 0; t < triangles.size(); ++t) triangles[t] = t;
    if (scene.materials.at(object.material).translucent()) {
      auto depth = [&](uint32_t t) {
        const uint32_t* i = &mesh.indices[3 * t];
        return farness((mesh.positions[i[0]] + mesh.positions[i[1]] + mesh.positions[i[2]]) / 3.0f);
      };
      std::stable_sort(triangles.begin(), triangles.end(), [&](uint32_t a, uint32_t b) { return depth(a) > depth(b); });
    }
    for (uint32_t t : triangles)
      for (int k = 0; k < 3; ++k) g.indices.push_back(base + mesh.indices[3 * t + uint32_t(k)]);
  }
  return g;
}

// The translucent draws far to near from the light (their centres'), as blended (JCGT §3).
void sort_translucent(std::vector<Draw>& translucent, const LightFarness& farness) {
  std::stable_sort(translucent.begin(), translucent.end(),
                   [&](const Draw& a, const Draw& b) { return farness(a.center) > farness(b.center); });
}

// The probe's cube map as a six-layer image (layer = face), the background of a probe-lit scene.
vk::Image upload_probe(const vk::Context& ctx, const scene::ProbeLighting& p) {
  probe::CubeMap cube;
  try {
    cube = probe::load_probe(p.file.string(), p.size, p.rotation_deg, p.intensity);
  } catch (const probe::ProbeError& e) { throw RenderError(e.what()); }
  std::vector<glm::vec4> texels;
  texels.reserve(std::size_t(6) * std::size_t(cube.size) * std::size_t(cube.size));
  for (const std::vector<glm::vec3>& face : cube.faces)
    for (const glm::vec3& L : face) texels.emplace_back(L, 1.0f);
  vk::Image image = vk::create_image(ctx, {.width = uint32_t(cube.size),
                                           .height = uint32_t(cube.size),
                                           .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                           .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                           .layers = 6});
  vk::upload_image(ctx, image, std::as_bytes(std::span(texels)), VK_IMAGE_LAYOUT_UNDEFINED,
                   VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  return image;
}

} // namespace

void refuse_unrendered_lights(const scene::Scene& scene) {
  for (const scene::LightKindInfo& kind : scene::light_kinds())
    if (!kind.rendered && scene.light_count(kind.kind) > 0)
      throw RenderError(fmt::format("the scene has {} {} light(s): the renderer draws {}; the ray tracer (msm "
                                    "reference) traces them",
                                    scene.light_count(kind.kind), kind.name, rendered_light_kinds()));
}

GpuScene::GpuScene(const vk::Context& ctx, const scene::Scene& scene) {
  refuse_unrendered_lights(scene);
  const Geometry g = geometry(scene);
  std::map<std::filesystem::path, int> texture_index;
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const scene::Object& object = scene.objects[o];
    const scene::Material& material = scene.materials.at(object.material);
    Draw draw;
    draw.object = uint32_t(o);
    draw.first_index = g.first_index[o];
    draw.index_count = uint32_t(object.mesh.indices.size());
    draw.center = object.bounds.center();
    if (!material.albedo_texture.empty()) { // a file, or "<mesh file>#<index>" for embedded ones
      auto [it, inserted] = texture_index.try_emplace(material.albedo_texture, int(textures.size()));
      if (inserted) {
        scene::Image texels = scene::albedo_image(material);
        textures.push_back(upload_texture(ctx, VK_FORMAT_R8G8B8A8_SRGB, texels.width, texels.height, texels.rgba));
      }
      draw.texture = it->second;
    }
    if (!material.opacity_texture.empty() || material.opacity_noise) {
      // One texture per material that has one (files and noise parameters may repeat; the
      // textures are small).
      scene::OpacityImage opacity = scene::opacity_image(material);
      draw.opacity_texture = int(opacity_textures.size());
      opacity_textures.push_back(
          upload_texture(ctx, VK_FORMAT_R8_UNORM, opacity.width, opacity.height, opacity.values));
    }
    draw.double_sided = material.double_sided;
    draw.push.albedo_opacity = glm::vec4(material.albedo, material.opacity);
    draw.push.flags =
        glm::ivec4(draw.texture >= 0 ? 1 : 0, material.double_sided ? 1 : 0, draw.opacity_texture >= 0 ? 1 : 0, -1);
    draw.masked = material.masked();
    draw.push.transmission = glm::vec4(material.transmission_color, material.alpha_cutoff.value_or(0.0f));
    if (!draw.index_count) continue;
    (material.translucent() ? translucent : draws).push_back(draw);
  }
  sort_translucent(translucent, translucent_farness(scene));
  vertices = vk::create_buffer(ctx, g.vertices.size() * sizeof(Vertex), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  vk::upload_buffer(ctx, vertices, std::as_bytes(std::span(g.vertices)));
  indices = vk::create_buffer(ctx, g.indices.size() * sizeof(uint32_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  vk::upload_buffer(ctx, indices, std::as_bytes(std::span(g.indices)));
  const std::uint8_t white_texel[4] = {255, 255, 255, 255};
  white = upload_texture(ctx, VK_FORMAT_R8G8B8A8_SRGB, 1, 1, white_texel);
  white_array = vk::create_image_view(ctx, white.handle(), white.format(), VK_IMAGE_ASPECT_COLOR_BIT,
                                      VK_IMAGE_VIEW_TYPE_2D_ARRAY, 0, 1, 0, 1);
  texture_sampler = vk::create_sampler(ctx, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT);
  if (scene.probe) probe = upload_probe(ctx, *scene.probe);
}

void GpuScene::move_objects(const vk::Context& ctx, const scene::Scene& scene) {
  const Geometry g = geometry(scene);
  if (g.vertices.size() * sizeof(Vertex) != vertices.size() || g.indices.size() * sizeof(uint32_t) != indices.size())
    throw RenderError("move_objects: the scene's objects differ from the renderer's (other meshes, not moved ones)");
  vk::upload_buffer(ctx, vertices, std::as_bytes(std::span(g.vertices)));
  vk::upload_buffer(ctx, indices, std::as_bytes(std::span(g.indices)));
  for (std::vector<Draw>* list : {&draws, &translucent})
    for (Draw& d : *list) d.center = scene.objects.at(d.object).bounds.center();
  sort_translucent(translucent, translucent_farness(scene));
}

} // namespace msm::render
