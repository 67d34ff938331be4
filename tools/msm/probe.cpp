// `msm probe`: a light probe (an equirectangular or cross EXR, or the procedural sky) split by the median cut
// into area lights (Kneiphof 2017): the table of lights, a scene "lights" list to render them with,
// and a picture of the cube map with the regions outlined.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "msm/image/io.h"
#include "msm/probe/probe.h"

namespace msm::tool {
namespace {

struct ProbeOptions {
  std::string probe;
  int size = 128;
  int lights = 32;
  float rotation_deg = 0.0f;
  float intensity = 1.0f;
  std::string scene_lights, cross;
};

// The horizontal cross (−X faces... laid out as  . +Y . . / −X +Z +X −Z / . −Y . .), tone mapped,
// with each region's border drawn in red.
image::Image cross_picture(const probe::CubeMap& cube, const std::vector<probe::Region>& regions) {
  const int m = cube.size;
  image::Image out(4 * m, 3 * m, 3);
  // (column, row) of each face in the cross; faces keep their texel orientation (row 0 at v = −1).
  const int cells[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
  for (int f = 0; f < 6; ++f)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const glm::vec3 c = cube.at(f, i, j);
        for (int k = 0; k < 3; ++k) out.at(cells[f][0] * m + i, cells[f][1] * m + j, k) = msm::msm_aces(c[k]);
      }
  for (const probe::Region& r : regions)
    for (int j = r.y0; j < r.y1; ++j)
      for (int i = r.x0; i < r.x1; ++i)
        if (i == r.x0 || j == r.y0 || i == r.x1 - 1 || j == r.y1 - 1) {
          const int x = cells[r.face][0] * m + i, y = cells[r.face][1] * m + j;
          out.at(x, y, 0) = 1.0f;
          out.at(x, y, 1) = out.at(x, y, 2) = 0.0f;
        }
  return out;
}

// Output files go where they are asked for, folders made as needed.
void make_parent(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code error;
  if (!parent.empty()) std::filesystem::create_directories(parent, error);
  if (error) throw UsageError(fmt::format("{}: cannot create the folder: {}", parent.string(), error.message()));
}

void run(const ProbeOptions& o) {
  probe::CubeMap cube;
  try {
    cube = o.probe == "sky" ? probe::sky_probe(o.size) : probe::load_probe(o.probe, o.size, o.rotation_deg);
  } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
  for (auto& face : cube.faces)
    for (glm::vec3& t : face) t *= o.intensity;
  const probe::ProbeTables tables(cube);
  std::vector<probe::Region> regions;
  try {
    regions = probe::median_cut(tables, o.lights);
  } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
  const std::vector<MsmAreaLight> lights = probe::area_lights(tables, regions);
  const glm::dvec3 total = probe::integrate(cube);
  fmt::print("probe {}: {}² texels per face, {} regions, {} lights; ∫L dω = ({:.4g}, {:.4g}, {:.4g})\n", o.probe,
             cube.size, regions.size(), lights.size(), total.x, total.y, total.z);
  fmt::print("{:>3}  {:>24}  {:>8}  {:>30}\n", "#", "towards light", "cone °", "irradiance M_e (RGB)");
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const MsmAreaLight& l = lights[k];
    fmt::print("{:>3}  ({:>6.3f}, {:>6.3f}, {:>6.3f})  {:>8.3f}  ({:>8.4g}, {:>8.4g}, {:>8.4g})\n", k, l.direction.x,
               l.direction.y, l.direction.z, glm::degrees(l.cone_half_angle), l.irradiance.x, l.irradiance.y,
               l.irradiance.z);
    const glm::vec3 facing = msm_area_light_facing_irradiance(l);
    // The scene's lights are discs of an angular diameter below 90°.
    const float diameter = std::min(2.0f * glm::degrees(l.cone_half_angle), 89.0f);
    list.push_back({{"towards_light", {l.direction.x, l.direction.y, l.direction.z}},
                    {"irradiance", {facing.x, facing.y, facing.z}},
                    {"angular_extent_deg", diameter}});
  }
  if (!o.scene_lights.empty()) {
    make_parent(o.scene_lights);
    const std::string text = nlohmann::json{{"lights", list}}.dump(2) + "\n";
    image::write_file_atomic(o.scene_lights,
                             std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    fmt::print("wrote {}\n", o.scene_lights);
  }
  if (!o.cross.empty()) {
    make_parent(o.cross);
    image::write_image(o.cross, cross_picture(cube, regions));
    fmt::print("wrote {}\n", o.cross);
  }
}

} // namespace

void add_probe(CLI::App& app) {
  auto options = std::make_shared<ProbeOptions>();
  auto* cmd = app.add_subcommand("probe", "Split a light probe into area lights by the median cut (Kneiphof 2017)");
  cmd->add_option("probe", options->probe,
                  "An equirectangular or cube-map cross (4:3, 3:4) EXR (e.g. "
                  "/usr/share/blender/datafiles/studiolights/world/studio.exr), or "
                  "'sky' for the procedural sky with a sun")
      ->required();
  cmd->add_option("--size", options->size, "Cube-map face size in texels")->check(CLI::Range(1, probe::kMaxCubeSize));
  cmd->add_option("--lights", options->lights, "Number of area lights (median-cut regions), 6 to 256")
      ->check(CLI::Range(6, 256));
  cmd->add_option("--rotation", options->rotation_deg, "Probe rotation about +Y in degrees");
  cmd->add_option("--intensity", options->intensity, "Radiance scale")->check(CLI::Range(0.0f, 1e6f));
  cmd->add_option("--scene-lights", options->scene_lights,
                  "Write the lights as a scene's \"lights\" list (JSON: direction, irradiance on a facing surface, "
                  "angular diameter)");
  cmd->add_option("--cross", options->cross, "Write the cube map as a cross with the regions outlined (.png or .exr)");
  cmd->callback([options] { run(*options); });
}

} // namespace msm::tool
