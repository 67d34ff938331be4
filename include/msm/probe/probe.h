// msm::probe: light probes as cube maps, and their median cut into area lights (Kneiphof 2017
// §3.1, §4.1) on the CPU: the reference the device implementation is checked against, and what
// `msm probe` prints. The per-texel and per-region formulas are include/msm/light_probe.h.
#pragma once

#include <array>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "msm/light_probe.h"

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

// Largest face size accepted (a 6 x 4096² RGB float cube map is 1.2 GB).
inline constexpr int kMaxCubeSize = 4096;

// An equirectangular (latitude-longitude) panorama of width x height RGB texels, row 0 at the
// zenith (+Y), column 0 at azimuth −π (direction −Z... see direction_of_equirect), resampled onto a
// cube map of `size`² faces: each cube texel averages ss² point samples of the panorama
// (bilinear, wrapping in longitude), so that panoramas finer than the cube are filtered, not
// aliased. rotation_deg turns the probe about +Y (counter-clockwise seen from above).
CubeMap cube_from_equirect(int width, int height, const std::vector<glm::vec3>& rgb, int size,
                           float rotation_deg = 0.0f, int supersampling = 4);

// Unit direction of the panorama point (s, t) in [0,1]²: azimuth φ = 2π s − π about +Y (φ = 0
// along −Z, increasing towards +X), polar angle θ = π t from +Y. Its inverse is equirect_of.
glm::vec3 direction_of_equirect(glm::vec2 st);
glm::vec2 equirect_of(glm::vec3 direction);

// An equirectangular EXR (any compression OpenEXR reads: ZIP, PIZ, DWAB, ...) as a cube map;
// throws ProbeError naming the file (missing, not an EXR, no R, G and B channels, a non-finite
// radiance, not 2:1). Negative values (lossy DWA compression rings below zero) are clamped to 0.
CubeMap load_equirect_probe(const std::filesystem::path& file, int size, float rotation_deg = 0.0f);

// A probe with an exact answer: a sky of constant radiance `sky` with a sun disc of radiance
// `sun` and angular radius `sun_radius_rad` around `towards_sun`; texels the disc's edge crosses
// average 16² point samples.
CubeMap make_sky_sun_probe(int size, glm::vec3 sky, glm::vec3 sun, glm::vec3 towards_sun, float sun_radius_rad);

// Σ over all texels of weight x radiance: the probe's ∫ L dω, linear RGB.
glm::dvec3 integrate(const CubeMap& cube);

// A rectangle of texels [x0, x1) x [y0, y1) of one face.
struct Region {
  int face = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double energy = 0.0; // Σ w Y over its texels (illuminance from luminance)
};

// Per-face summed-area tables of w X, w Y, w Z, w Y u, w Y v, w Y u², w Y v² (double), so that
// any region's MsmRegionSums cost O(1).
class ProbeTables {
 public:
  explicit ProbeTables(const CubeMap& cube);
  int size() const { return size_; }
  MsmRegionSums sums(const Region& r) const;
  double energy(const Region& r) const; // Σ w Y
 private:
  int size_ = 0;
  // tables_[face][k] is (size + 1)² entries, entry (x, y) = sum over texels [0, x) x [0, y).
  std::array<std::array<std::vector<double>, 7>, 6> tables_;
  double rect(int face, int k, const Region& r) const;
};

// The median cut (Kneiphof §3.1 after Debevec's): one region per face, then the region with the
// largest energy is split across its longer side (the other side where the longer is one texel)
// where the energy of the two parts is closest to equal, until there are `count` regions; regions
// of one texel are not split. Regions never straddle faces, so count must be in [6, 256]
// (ProbeError otherwise); a probe with fewer splittable texels than needed returns fewer regions.
std::vector<Region> median_cut(const ProbeTables& tables, int count);

// The area lights of the regions (msm_area_light_from_region), regions without energy skipped.
std::vector<MsmAreaLight> area_lights(const ProbeTables& tables, const std::vector<Region>& regions);

// The whole CPU pipeline: the probe (an equirectangular EXR, or "sky" for make_sky_sun_probe's
// default sky: see sky_probe) as a cube map of size², scaled by intensity, cut into `count`
// regions, and their area lights.
std::vector<MsmAreaLight> probe_area_lights(const std::string& probe, int size, int count, float rotation_deg = 0.0f,
                                            float intensity = 1.0f);
// The cube map probe_area_lights cuts: the probe ("sky" or an equirectangular EXR) at size²,
// turned by rotation_deg about +Y and scaled by intensity. The ray tracer's environment ground
// truth lights the scene with exactly this (msm::reference, effect environment).
CubeMap load_probe(const std::string& probe, int size, float rotation_deg = 0.0f, float intensity = 1.0f);
// The procedural sky of `msm probe sky` and of scenes with "file": "sky": a blue sky of radiance
// (0.15, 0.22, 0.4) all around and a sun disc of radius 0.27° and radiance (40000, 36000, 30000)
// towards (0.4, 0.6, −0.3): on a horizontal surface the sun brings about four times the sky's
// luminance, as on a clear day. rotation_deg turns it about +Y as cube_from_equirect does.
CubeMap sky_probe(int size, float rotation_deg = 0.0f);

} // namespace msm::probe
