// msm::probe: light probes as cube maps, and their median cut into area lights (Kneiphof 2017
// §3.1, §4.1) on the CPU: the reference the device implementation is checked against, and what
// `msm probe` prints. The per-texel and per-region formulas are include/msm/light_probe.h.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "msm/light_probe.h"
#include "msm/median_cut.h"

namespace msm::probe {

class ProbeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Six square faces of linear RGB radiance, Vulkan's layer order and orientation (light_probe.h).
struct CubeMap {
  int size = 0;                                // texels per side
  std::array<std::vector<glm::vec3>, 6> faces; // row-major, row j at v = (2 j + 1) / size − 1
  glm::vec3& at(int face, int i, int j) { return faces[face][std::size_t(j) * size + i]; }
  const glm::vec3& at(int face, int i, int j) const { return faces[face][std::size_t(j) * size + i]; }
};

// A cube map of size² faces whose texel (face, i, j) is texel(face, i, j), filled face by face and
// row by row.
template <typename Texel>
CubeMap make_cube(int size, Texel&& texel) {
  CubeMap cube;
  cube.size = size;
  for (int face = 0; face < 6; ++face) {
    cube.faces[face].resize(std::size_t(size) * size);
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) cube.at(face, i, j) = texel(face, i, j);
  }
  return cube;
}

// Largest face size accepted (a 6 x 4096² RGB float cube map is 1.2 GB).
inline constexpr int kMaxCubeSize = 4096;
// Largest radiance a probe texel may hold, after its intensity (load_equirect, load_probe: a
// ProbeError above it). The cut's float sums (luminance times solid angle, over the cube) and the
// lights' irradiance must stay finite: a probe of 1e37 everywhere gave lights towards (0, 0, 0)
// and an infinite integral (read as "the probe is black"). 1e20 is far above any real probe (a
// sun of 1e9) and leaves the renderer's products in float.
inline constexpr float kMaxProbeRadiance = 1e20f;

// An equirectangular (latitude-longitude) panorama of width x height RGB texels, row 0 at the
// zenith (+Y), column 0 at azimuth −π (direction −Z... see direction_of_equirect), resampled onto a
// cube map of `size`² faces: each cube texel averages ss² point samples of the panorama
// (bilinear, wrapping in longitude), so that panoramas finer than the cube are filtered, not
// aliased. rotation_deg turns the probe about +Y (counter-clockwise seen from above).
CubeMap cube_from_equirect(int width, int height, const std::vector<glm::vec3>& rgb, int size,
                           float rotation_deg = 0.0f, int supersampling = 4);

// (cos, sin) of a probe rotation about +Y in degrees (computed in double), as
// msm_probe_lookup_direction takes it.
glm::vec2 rotation_cos_sin(float rotation_deg);

// Unit direction of the panorama point (s, t) in [0,1]²: azimuth φ = 2π s − π about +Y (φ = 0
// along −Z, increasing towards +X), polar angle θ = π t from +Y. Its inverse is equirect_of
// (msm_equirect_of, in float as cube_from_equirect and the device use it).
glm::vec3 direction_of_equirect(glm::vec2 st);
glm::vec2 equirect_of(glm::vec3 direction);

// An equirectangular panorama of linear RGB radiance, row 0 at the zenith.
struct Panorama {
  int width = 0, height = 0;
  std::vector<glm::vec3> rgb; // row-major
};
// An equirectangular EXR as it is (the checks and clamping of load_equirect_probe, no resampling):
// what the device pipeline (DeviceProbe) resamples itself.
Panorama load_equirect(const std::filesystem::path& file);
// How a probe picture is laid out, told by its shape alone: a panorama is 2:1 (width = 2 height), a
// cube-map cross 4:3 or 3:4 (cube_from_cross); any other shape, or an empty one, is neither. The one rule that
// load_probe_file and the frame sequences' device probe read: only a panorama can be rotated.
enum class PictureLayout { panorama, cross, neither };
PictureLayout picture_layout(int width, int height);

// An equirectangular EXR (any compression OpenEXR reads: ZIP, PIZ, DWAB, ...) as a cube map;
// throws ProbeError naming the file (missing, not an EXR, no R, G and B channels, a non-finite
// radiance, not 2:1). Negative values (lossy DWA compression rings below zero) are clamped to 0.
CubeMap load_equirect_probe(const std::filesystem::path& file, int size, float rotation_deg = 0.0f);

// Cube-map probes. A cross is one image of six square faces of side s, each in its texel
// orientation (light_probe.h: texel (i, j) at column i, row j of its cell, row 0 the top), so that
// neighbouring faces continue each other across the cell borders:
//   horizontal, 4s x 3s (the layout `msm probe --cross` writes):   vertical, 3s x 4s:
//        .  +Y  .   .                                                .  +Y  .
//       −X  +Z  +X  −Z                                              −X  +Z  +X
//        .  −Y  .   .                                                .  −Y  .
//                                                                    .  −Z  .   (−Z turned by 180°)
// The cells outside the faces are ignored. Throws ProbeError for any other shape.
CubeMap cube_from_cross(int width, int height, const std::vector<glm::vec3>& rgb);
// The cross of a cube map (the inverse of cube_from_cross; horizontal or vertical), RGB texels.
std::vector<glm::vec3> cross_of_cube(const CubeMap& cube, bool vertical);
// Six face images, one per layer (+X, −X, +Y, −Y, +Z, −Z), square and of one size.
CubeMap cube_from_faces(const std::array<int, 6>& sizes, const std::array<std::vector<glm::vec3>, 6>& faces);
// A cube map box-filtered down to size² faces; size must divide cube.size (ProbeError otherwise).
CubeMap downsample_cube(const CubeMap& cube, int size);
// A probe file as a cube map of size² faces: an equirectangular panorama (2:1, as
// load_equirect_probe) or a cross EXR (4:3 or 3:4; the faces box-filtered to `size`, which must
// divide their side; rotation_deg must be 0 for a cross), or six face files named by a "{face}"
// path (below).
// A path holding "{face}" names six face files, one square EXR per face: "{face}" stands for px,
// nx, py, ny, pz, nz (+X, −X, +Y, −Y, +Z, −Z, Vulkan's cube faces: msm_cube_direction), e.g.
// "probe/{face}.exr"; load_probe_file reads them through load_cube_faces (they cannot be rotated,
// as a cross cannot).
bool is_cube_faces_path(const std::filesystem::path& file);
std::array<std::filesystem::path, 6> cube_face_files(const std::filesystem::path& pattern);
// The files a probe path reads: its six faces for a "{face}" path, else the path itself.
std::vector<std::filesystem::path> probe_input_files(const std::filesystem::path& file);
// The cube map as six RGB EXR faces named by a "{face}" path (ProbeError otherwise): each written
// under a temporary name first, all six renamed at the end, so that a failure leaves none.
void write_cube_faces(const std::filesystem::path& pattern, const CubeMap& cube);
CubeMap load_probe_file(const std::filesystem::path& file, int size, float rotation_deg = 0.0f);
CubeMap load_cube_faces(const std::array<std::filesystem::path, 6>& files, int size);

// A probe with an exact answer: a sky of constant radiance `sky` with a sun disc of radiance
// `sun` and angular radius `sun_radius_rad` around `towards_sun`; texels the disc's edge crosses
// average 16² point samples.
CubeMap make_sky_sun_probe(int size, glm::vec3 sky, glm::vec3 sun, glm::vec3 towards_sun, float sun_radius_rad);

// Σ over all texels of weight x radiance: the probe's ∫ L dω, linear RGB.
glm::dvec3 integrate(const CubeMap& cube);

// A rectangle of texels [x0, x1) x [y0, y1) of one face; or, for cuts into fewer than six regions
// (median_cut), a group of whole faces: `faces` has bit f set for each face f of the group, `face`
// is its lowest face and the rectangle that face's whole square (region_parts lists the faces).
struct Region {
  int face = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double energy = 0.0;            // Σ w Y over its texels (illuminance from luminance)
  std::uint64_t fixed_energy = 0; // the same in the tables' fixed point (ProbeTables::scale), what the cut compares
  std::uint32_t faces = 0;        // a group of whole faces (N < 6): bit f per face f; 0: the rectangle of `face`
  bool operator==(const Region&) const = default;
};

// The rectangles a region is made of: itself, or one whole face (of size² texels) per face of a
// group, in increasing face order (energies not set).
std::vector<Region> region_parts(const Region& r, int size);

// The solid-angle weights msm_cube_texel_weight of one face's texels (row-major, the same on every
// face) and the coordinates of the texel centres msm_cube_face_coordinate (u of column i = v of row
// i): computed on the host for the CPU tables and uploaded for the device's.
std::vector<float> texel_weights(int size);
std::vector<float> face_coordinates(int size);

// The power of two by which the fixed-point tables scale every texel value (light_probe.h,
// msm_probe_texel) for a probe whose largest RGB component is max_component: 2^(60 − e) where
// max_component < 2^e, so that a face's sums (at most 2 · 2π/3 · max_component · scale) stay below
// 2^63; 1 for a black probe. Exponents are kept in [−100, 100] (float range, no denormals).
float table_scale(float max_component);

// Per-face summed-area tables of w X, w Y, w Z, w Y (1 + u), w Y (1 + v), w Y u², w Y v² in
// fixed point (uint64, see msm_probe_texel), so that any region's MsmRegionSums cost O(1) and the
// median cut compares exact integers: the device builds the same tables bit for bit
// (msm::probe::DeviceProbe), so both cut the same regions.
class ProbeTables {
 public:
  // scale 0: table_scale of the cube's largest component.
  explicit ProbeTables(const CubeMap& cube, float scale = 0.0f);
  int size() const { return size_; }
  float scale() const { return scale_; }
  MsmRegionSums sums(const Region& r) const;         // of the rectangle of r.face (one part of a group)
  double energy(const Region& r) const;              // Σ w Y (of every face of a group)
  std::uint64_t fixed_energy(const Region& r) const; // Σ w Y times scale, as the tables hold it
  // Entry (x, y) of table k (0..6, the order above) of a face: the sum over texels [0, x) x [0, y).
  std::uint64_t at(int face, int k, int x, int y) const {
    return tables_[face][k][std::size_t(y) * (std::size_t(size_) + 1) + std::size_t(x)];
  }

 private:
  int size_ = 0;
  float scale_ = 1.0f;
  // tables_[face][k] is (size + 1)² entries, entry (x, y) = sum over texels [0, x) x [0, y).
  std::array<std::array<std::vector<std::uint64_t>, 7>, 6> tables_;
  std::uint64_t rect(int face, int k, const Region& r) const;
};

// The median cut (Kneiphof §3.1 after Debevec's): one region per face, then the region with the
// largest energy (fixed_energy; ties: the earliest in the list) is split across its longer side (the other side where the longer is one texel)
// where the energy of the two parts is closest to equal, until there are `count` regions; regions
// of one texel are not split. A probe with fewer splittable texels than needed returns fewer
// regions. count must be in [1, 256] (ProbeError otherwise). Below 6, the six face regions are
// merged instead: while there are more than `count`, the two regions with the least energy
// together (fixed_energy, exact integers) among those that share a cube edge (a face of one next
// to a face of the other: not opposite faces) become one (ties: the first pair (i, j), i < j, in
// the list's order; the merged region takes the first's place, the second leaves the list), so a
// region is a group of whole, edge-connected faces (Region::faces; docs/techniques.md says why).
//
// horizon_split: the cut starts from ten regions instead of six, each side face (±X, ±Z) halved at
// its middle row, the world's horizon (msm_first_region, whatever the probe's rotation about +Y), so
// that no region, and no light's region, straddles the horizon of an upward-facing receiver
// (docs/techniques.md). It needs count >= kHorizonSplitMinLights and an even face size
// (ProbeError otherwise: fewer lights would merge halves across the horizon again).
inline constexpr int kHorizonSplitMinLights = 10;
void check_cut(int count, int size, bool horizon_split); // the ProbeErrors of median_cut's arguments
std::vector<Region> median_cut(const ProbeTables& tables, int count, bool horizon_split = false);

// The area lights of the regions (msm_area_light_from_region; a group of faces:
// msm_area_light_from_merged of its faces in increasing order), regions without energy skipped.
std::vector<MsmAreaLight> area_lights(const ProbeTables& tables, const std::vector<Region>& regions);

// Sub-lights (a probe's "sub_lights", docs/techniques.md): the regions of the finer cut `fine`
// (median_cut into more regions, the same horizon_split) that lie in each region of `coarse`, by
// index into `fine`. The median cut only ever splits, and a cut into more regions goes through
// the cut into fewer, so every fine region lies in exactly one coarse region (a rectangle inside
// the coarse rectangle of its face, or a face of a coarse group of faces); ProbeError if one does
// not (cuts of different probes or tables).
std::vector<std::vector<int>> sub_regions(const std::vector<Region>& coarse, const std::vector<Region>& fine);

// A light of the cut and the lights of the finer cut's regions inside its region: the light shades
// its unshadowed irradiance as the sum of its sub-lights' (each a uniform rectangle of its own,
// smaller region), its shadow stays its own.
struct ProbeLight {
  MsmAreaLight light;
  std::vector<MsmAreaLight> sub_lights;
};
// A cut's regions in median_cut's order and the area lights of those with energy (area_lights'
// order): light_of_region[k] is region k's light, −1 for none. The device's cut reads back the same
// (DeviceCut).
struct CutLights {
  std::vector<Region> regions;
  std::vector<MsmAreaLight> lights;
  std::vector<int> light_of_region;
};
CutLights cut_lights(const ProbeTables& tables, int count, bool horizon_split = false);
// The coarse cut's lights, each with the fine cut's lights that lie in its region (sub_regions;
// ProbeError if the cuts do not nest).
std::vector<ProbeLight> with_sub_lights(const CutLights& coarse, const CutLights& fine);
// Whether a cut into `count` regions gets sub-lights from one into `sub_count`: only a finer cut
// (at most `count` regions, each light would be its own single sub-light).
inline bool sub_lights_refine(int count, int sub_count) { return sub_count > count; }
// The cut into `count` regions' area lights (area_lights: regions without energy skipped), each
// with its sub-lights from the cut into sub_count regions (their lights likewise); none unless
// sub_lights_refine(count, sub_count).
std::vector<ProbeLight> lights_with_sub_lights(const ProbeTables& tables, int count, int sub_count,
                                               bool horizon_split = false);
// probe_area_lights with each light's sub-lights (lights_with_sub_lights).
std::vector<ProbeLight> probe_lights_with_sub_lights(const std::string& probe, int size, int count, int sub_count,
                                                     float rotation_deg = 0.0f, float intensity = 1.0f,
                                                     bool horizon_split = false);

// The whole CPU pipeline: the probe (an equirectangular or cross EXR, load_probe_file, or "sky" for
// make_sky_sun_probe's default sky: see sky_probe) as a cube map of size², scaled by intensity, cut into `count`
// regions (median_cut, horizon_split as there), and their area lights.
std::vector<MsmAreaLight> probe_area_lights(const std::string& probe, int size, int count, float rotation_deg = 0.0f,
                                            float intensity = 1.0f, bool horizon_split = false);
// The cube map probe_area_lights cuts: the probe ("sky" or an EXR, load_probe_file) at size²,
// turned by rotation_deg about +Y and scaled by intensity. The ray tracer's environment ground
// truth lights the scene with exactly this (msm::reference, effect environment).
CubeMap load_probe(const std::string& probe, int size, float rotation_deg = 0.0f, float intensity = 1.0f);
// The procedural sky of `msm probe sky` and of scenes with "file": "sky": a blue sky of radiance
// (0.15, 0.22, 0.4) all around and a sun disc of radius 0.27° and radiance (40000, 36000, 30000)
// towards (0.4, 0.6, −0.3): on a horizontal surface the sun brings about four times the sky's
// luminance, as on a clear day. rotation_deg turns it about +Y as cube_from_equirect turns a
// panorama (the sun's direction turns with it).
CubeMap sky_probe(int size, float rotation_deg = 0.0f);

} // namespace msm::probe
