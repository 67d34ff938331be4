// `msm lights` (and `msm probe`, its name in the first release, with the old options): a light
// probe (an equirectangular or cube-map cross EXR, or the procedural sky) split by the median cut into area lights
// (Kneiphof 2017): the table of lights (or JSON), a scene "lights" list to render them with, and a
// picture of the cube map with the regions outlined. A black probe gives no lights (and a black
// picture), exit status 0; a bad probe or count is a UsageError (exit status 2).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "msm/image/io.h"
#include "msm/probe/probe.h"
#include "msm/scene/scene.h"
#include "usage.h"
#include "vocabulary.h"

namespace msm::tool {
namespace {

struct LightsOptions {
  std::string probe;
  int size = 128;
  int count = 32;
  int sub_lights = 0; // the finer cut whose lights each light's sub-lights are (0 or <= count: none)
  float rotation_deg = 0.0f;
  float intensity = 1.0f;
  bool json = false;
  bool horizon_split = false;
  std::string scene_lights, picture;
  std::string faces; // a "{face}" path: the cube map written as six EXR faces
};

// The face across each edge of a face: [face][edge], edges u = −1, u = +1, v = −1, v = +1.
int face_across(int face, int edge) {
  const float u = edge == 0 ? -1.5f : edge == 1 ? 1.5f : 0.0f, v = edge == 2 ? -1.5f : edge == 3 ? 1.5f : 0.0f;
  return msm_cube_coord(msm_cube_direction(face, u, v)).face;
}

// The horizontal cross (−X faces... laid out as  . +Y . . / −X +Z +X −Z / . −Y . .), tone mapped,
// with each region's border drawn in red (a group of faces: the edges of its faces that it does not
// share with another of its faces).
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
  for (const probe::Region& region : regions)
    for (const probe::Region& r : probe::region_parts(region, m)) {
      bool edge[4] = {true, true, true, true}; // u = −1, u = +1, v = −1, v = +1
      if (region.faces != 0)
        for (int e = 0; e < 4; ++e) edge[e] = !(region.faces & (1u << face_across(r.face, e)));
      for (int j = r.y0; j < r.y1; ++j)
        for (int i = r.x0; i < r.x1; ++i) {
          if (!((i == r.x0 && edge[0]) || (i == r.x1 - 1 && edge[1]) || (j == r.y0 && edge[2]) ||
                (j == r.y1 - 1 && edge[3])))
            continue;
          const int x = cells[r.face][0] * m + i, y = cells[r.face][1] * m + j;
          out.at(x, y, 0) = 1.0f;
          out.at(x, y, 1) = out.at(x, y, 2) = 0.0f;
        }
    }
  return out;
}

// A light's half extents in degrees (its tangents' angles) along its x and y axes.
glm::vec2 half_extent_deg(const MsmAreaLight& l) {
  return glm::degrees(glm::vec2(std::atan(l.half_extent.x), std::atan(l.half_extent.y)));
}

// Σ of the texels' solid angles (msm_cube_texel_weight) over a region.
double solid_angle(const probe::Region& region, int size) {
  double sum = 0.0;
  for (const probe::Region& r : probe::region_parts(region, size))
    for (int j = r.y0; j < r.y1; ++j)
      for (int i = r.x0; i < r.x1; ++i)
        sum += msm_cube_texel_weight((2.0f * i + 1.0f) / size - 1.0f, (2.0f * j + 1.0f) / size - 1.0f, float(size));
  return sum;
}

// Output files go where they are asked for, folders made as needed.
void make_parent(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code error;
  if (!parent.empty()) std::filesystem::create_directories(parent, error);
  if (error) throw UsageError(fmt::format("{}: cannot create the folder: {}", parent.string(), error.message()));
}

nlohmann::json vec(glm::vec3 v) { return {v.x, v.y, v.z}; }

// Checked here, not by CLI11, so that a bad value is a failed command (exit 2) naming the range.
void check_options(const LightsOptions& o) {
  if (o.count < 1 || o.count > 256)
    throw UsageError(fmt::format("--lights {}: the median cut makes 1 to 256 lights", o.count));
  if (o.sub_lights < 0 || o.sub_lights > 256)
    throw UsageError(fmt::format("--sub-lights {}: expected 0 (none) to 256", o.sub_lights));
  if (o.size < 1 || o.size > probe::kMaxCubeSize)
    throw UsageError(
        fmt::format("--size {}: the cube map's faces are 1 to {} texels wide", o.size, probe::kMaxCubeSize));
  if (!(std::isfinite(o.intensity) && o.intensity >= 0.0f && o.intensity <= 1e6f))
    throw UsageError(fmt::format("--intensity {}: expected 0 to 1e6", o.intensity));
  if (!(std::isfinite(o.rotation_deg) && std::abs(o.rotation_deg) <= 360.0f))
    throw UsageError(fmt::format("--rotation {}: expected -360 to 360 degrees", o.rotation_deg));
  if (!o.picture.empty()) { // before anything is written: no list without its picture
    std::string ext = std::filesystem::path(o.picture).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".png" && ext != ".exr")
      throw UsageError(fmt::format("--picture {}: expected a .png or .exr", o.picture));
  }
  if (!o.faces.empty() && (!probe::is_cube_faces_path(o.faces) || std::filesystem::path(o.faces).extension() != ".exr"))
    throw UsageError(
        fmt::format("--faces {}: expected a path with \"{{face}}\" ending in .exr, e.g. probe_{{face}}.exr", o.faces));
  try {
    probe::check_cut(o.count, o.size, o.horizon_split); // --horizon-split: count >= 10, size even
    if (probe::sub_lights_refine(o.count, o.sub_lights)) probe::check_cut(o.sub_lights, o.size, o.horizon_split);
  } catch (const probe::ProbeError& e) { throw UsageError(fmt::format("--horizon-split: {}", e.what())); }
}

// The probe's cube map cut into lights with their regions (cut_lights skips regions without energy,
// Σ w Y = 0 in the tables: a black probe has none), and each light's sub-lights: the lights of the cut
// into --sub-lights regions inside its region, as a scene's "sub_lights" gives them to the renderer.
struct ProbeCut {
  probe::CubeMap cube;
  probe::CutLights cut;
  std::vector<probe::ProbeLight> grouped; // empty without sub-lights
  std::vector<probe::Region> lit;         // the region of each light
};

ProbeCut cut_probe(const LightsOptions& o) {
  ProbeCut c;
  try {
    c.cube = probe::load_probe(o.probe, o.size, o.rotation_deg, o.intensity);
  } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
  const probe::ProbeTables tables(c.cube);
  try {
    c.cut = probe::cut_lights(tables, o.count, o.horizon_split);
    if (probe::sub_lights_refine(o.count, o.sub_lights))
      c.grouped = probe::with_sub_lights(c.cut, probe::cut_lights(tables, o.sub_lights, o.horizon_split));
  } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
  c.lit.resize(c.cut.lights.size());
  for (std::size_t r = 0; r < c.cut.regions.size(); ++r)
    if (c.cut.light_of_region[r] >= 0) c.lit[std::size_t(c.cut.light_of_region[r])] = c.cut.regions[r];
  return c;
}

// A light as a scene's "lights" entry: a rectangle of angular width and height below 90°
// (light_of_area_light).
nlohmann::json scene_light(const MsmAreaLight& l) {
  const scene::DirectionalLight drawn = scene::light_of_area_light(l);
  return {{"towards_light", vec(drawn.towards_light)},
          {"irradiance", vec(drawn.irradiance)},
          {"angular_extent_deg", drawn.angular_extent_deg},
          {"angular_height_deg", *drawn.angular_height_deg},
          {"x_axis", vec(*drawn.x_axis)}};
}

nlohmann::json region_json(const probe::Region& r, int cube_size) {
  nlohmann::json region = {{"face", r.face}, {"x", {r.x0, r.x1}}, {"y", {r.y0, r.y1}}};
  if (r.faces != 0) { // a group of whole faces (N < 6)
    nlohmann::json faces = nlohmann::json::array();
    for (const probe::Region& part : probe::region_parts(r, cube_size)) faces.push_back(part.face);
    region["faces"] = faces;
  }
  return region;
}

// Light k's row of the JSON table, with its sub-lights when the cut has them.
nlohmann::json light_entry(const ProbeCut& c, std::size_t k) {
  const MsmAreaLight& l = c.cut.lights[k];
  const glm::vec2 half_deg = half_extent_deg(l);
  nlohmann::json entry = {{"direction", vec(l.direction)},
                          {"x_axis", vec(l.x_axis)},
                          {"y_axis", vec(l.y_axis)},
                          {"half_extent_deg", {half_deg.x, half_deg.y}},
                          {"cone_half_angle_deg", glm::degrees(l.cone_half_angle)},
                          {"solid_angle_sr", solid_angle(c.lit[k], c.cube.size)},
                          {"irradiance", vec(l.irradiance)},
                          {"facing_irradiance", vec(msm_area_light_facing_irradiance(l))},
                          {"region", region_json(c.lit[k], c.cube.size)}};
  if (!c.grouped.empty()) {
    nlohmann::json subs = nlohmann::json::array();
    for (const MsmAreaLight& sub : c.grouped[k].sub_lights)
      subs.push_back({{"direction", vec(sub.direction)},
                      {"x_axis", vec(sub.x_axis)},
                      {"half_extent_deg", {half_extent_deg(sub).x, half_extent_deg(sub).y}},
                      {"irradiance", vec(sub.irradiance)}});
    entry["sub_lights"] = subs;
  }
  return entry;
}

// The text form: a line about the probe, then the table of lights and a line about their sub-lights.
void print_table(const LightsOptions& o, const ProbeCut& c, const glm::dvec3& total) {
  const std::vector<MsmAreaLight>& lights = c.cut.lights;
  fmt::print("probe {}: {}² texels per face, {} regions, {} lights{}; ∫L dω = ({:.4g}, {:.4g}, {:.4g})\n", o.probe,
             c.cube.size, c.cut.regions.size(), lights.size(), lights.empty() ? " (the probe is black)" : "", total.x,
             total.y, total.z);
  if (!lights.empty())
    fmt::print("{:>3}  {:>24}  {:>15}  {:>7}  {:>8}  {:>30}\n", "#", "towards light", "half-extents °", "Ω sr",
               "cone °", "irradiance M_e (RGB)");
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const MsmAreaLight& l = lights[k];
    const glm::vec2 half_deg = half_extent_deg(l);
    fmt::print("{:>3}  ({:>6.3f}, {:>6.3f}, {:>6.3f})  {:>6.2f} x {:>6.2f}  {:>7.4f}  {:>8.3f}  ({:>8.4g}, {:>8.4g}, "
               "{:>8.4g})\n",
               k, l.direction.x, l.direction.y, l.direction.z, half_deg.x, half_deg.y,
               solid_angle(c.lit[k], c.cube.size), glm::degrees(l.cone_half_angle), l.irradiance.x, l.irradiance.y,
               l.irradiance.z);
  }
  if (c.grouped.empty()) return;
  std::size_t fewest = c.grouped.front().sub_lights.size(), most = fewest, total_subs = 0;
  for (const probe::ProbeLight& g : c.grouped) {
    fewest = std::min(fewest, g.sub_lights.size());
    most = std::max(most, g.sub_lights.size());
    total_subs += g.sub_lights.size();
  }
  fmt::print("sub-lights: {} lights of the cut into {} regions, {} to {} per light (--json lists them)\n", total_subs,
             o.sub_lights, fewest, most);
}

// The files asked for, each written whole under a temporary name, then renamed.
void write_files(const LightsOptions& o, const ProbeCut& c) {
  const auto wrote = [&](const std::string& path) {
    if (o.json)
      fmt::print(stderr, "wrote {}\n", path);
    else
      fmt::print("wrote {}\n", path);
  };
  if (!o.scene_lights.empty()) {
    make_parent(o.scene_lights);
    nlohmann::json list = nlohmann::json::array();
    for (const MsmAreaLight& l : c.cut.lights) list.push_back(scene_light(l));
    const std::string text = nlohmann::json{{"lights", list}}.dump(2) + "\n";
    image::write_file_atomic(o.scene_lights,
                             std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    wrote(o.scene_lights);
  }
  if (!o.picture.empty()) {
    make_parent(o.picture);
    try {
      image::write_image(o.picture, cross_picture(c.cube, c.cut.regions));
    } catch (const image::ImageError& e) { throw UsageError(e.what()); }
    wrote(o.picture);
  }
  if (!o.faces.empty()) {
    make_parent(o.faces);
    try {
      probe::write_cube_faces(o.faces, c.cube);
    } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
    for (const std::filesystem::path& face : probe::cube_face_files(o.faces)) wrote(face.string());
  }
}

void run(const LightsOptions& o) {
  check_options(o);
  const ProbeCut c = cut_probe(o);
  const glm::dvec3 total = probe::integrate(c.cube);
  if (!o.json) print_table(o, c, total);
  write_files(o, c);
  if (!o.json) return;
  nlohmann::ordered_json doc;
  doc["probe"] = o.probe;
  doc["size"] = c.cube.size;
  doc["rotation_deg"] = o.rotation_deg;
  doc["intensity"] = o.intensity;
  doc["horizon_split"] = o.horizon_split;
  doc["regions"] = c.cut.regions.size();
  doc["sub_lights"] = c.grouped.empty() ? 0 : o.sub_lights;
  doc["integral"] = {total.x, total.y, total.z};
  nlohmann::json table = nlohmann::json::array();
  for (std::size_t k = 0; k < c.cut.lights.size(); ++k) table.push_back(light_entry(c, k));
  doc["lights"] = table;
  fmt::print("{}\n", doc.dump(2));
}

} // namespace

void add_lights(CLI::App& app) {
  const std::string probe_help =
      "An equirectangular or cube-map cross (4:3, 3:4) EXR (e.g. /usr/share/blender/datafiles/studiolights/world/"
      "studio.exr), six face EXRs named by a path with \"{face}\" (px nx py ny pz nz), or 'sky' for the procedural "
      "sky with a sun";
  const std::string probe_detail = " (e.g. /usr/share/blender/datafiles/studiolights/world/studio.exr; the six faces "
                                   "px nx py ny pz nz; 'sky': the procedural sky with a sun)";
  const std::string scene_lights_help = "Write the lights as a scene's \"lights\" list (JSON: direction, irradiance "
                                        "on a facing surface, angular diameter)";
  const std::string picture_help = "Write the cube map as a cross with the regions outlined (.png or .exr)";
  {
    auto o = std::make_shared<LightsOptions>();
    auto* cmd = app.add_subcommand(
        "lights", "A light probe's area lights by the median cut (Kneiphof 2017): direction, extents, solid angle, "
                  "irradiance; a picture of the regions");
    add_term(cmd, "--probe", o->probe, probe_detail)->required();
    add_term(cmd, "--lights", o->count, " (default 32)");
    add_deprecated_option(cmd, "--count", "--lights", o->count);
    add_term_flag(cmd, "--json", o->json, ": the lights");
    cmd->add_option("--size", o->size, "Cube-map face size in texels (default 128)");
    cmd->add_option("--rotation", o->rotation_deg, "Probe rotation about +Y in degrees");
    cmd->add_option("--intensity", o->intensity, "Radiance scale (default 1)");
    cmd->add_option("--picture", o->picture, picture_help);
    cmd->add_option("--faces", o->faces,
                    "Write the cube map the cut sees (--size, --rotation, --intensity applied) as six EXR faces named "
                    "by a path with \"{face}\" (px nx py ny pz nz): a probe for scenes and --probe");
    cmd->add_flag("--horizon-split", o->horizon_split,
                  "Start the cut from the side faces halved at the horizon (10 regions: --lights 10 to 256, even "
                  "--size), so that no light straddles the horizon");
    cmd->add_option("--scene-lights", o->scene_lights, scene_lights_help);
    add_term(cmd, "--sub-lights", o->sub_lights,
             ", as a scene's \"sub_lights\" shades them (listed by --json; no more than --lights: none)");
    cmd->callback([o] { run(*o); });
  }
  {
    auto o = std::make_shared<LightsOptions>();
    auto* cmd = app.add_subcommand("probe", "The first name of msm lights: msm probe PROBE --lights N [--cross F]");
    cmd->add_option("probe", o->probe, probe_help)->required();
    cmd->add_option("--size", o->size, "Cube-map face size in texels");
    add_term(cmd, "--lights", o->count);
    cmd->add_option("--rotation", o->rotation_deg, "Probe rotation about +Y in degrees");
    cmd->add_option("--intensity", o->intensity, "Radiance scale");
    cmd->add_option("--scene-lights", o->scene_lights, scene_lights_help);
    cmd->add_option("--cross", o->picture, picture_help);
    add_term_flag(cmd, "--json", o->json, ": the lights");
    cmd->callback([o] { run(*o); });
  }
}

} // namespace msm::tool
