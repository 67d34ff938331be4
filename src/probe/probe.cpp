// Light probes on the CPU: equirectangular resampling, the procedural sky, summed-area tables
// and the median cut (include/msm/probe/probe.h).
#include "msm/probe/probe.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "msm/image/io.h"

namespace msm::probe {
namespace {

constexpr double kPi = 3.14159265358979323846;

float face_coordinate(int i, int size, float offset = 0.5f) {
  return (2.0f * (float(i) + offset)) / float(size) - 1.0f;
}

void check_size(int size) {
  if (size < 1 || size > kMaxCubeSize)
    throw ProbeError(fmt::format("cube map size {} outside 1..{}", size, kMaxCubeSize));
}

} // namespace

glm::vec3 direction_of_equirect(glm::vec2 st) {
  const double phi = 2.0 * kPi * st.x - kPi, theta = kPi * st.y;
  return glm::vec3(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                   float(-std::sin(theta) * std::cos(phi)));
}

glm::vec2 equirect_of(glm::vec3 d) {
  const glm::dvec3 n = glm::normalize(glm::dvec3(d));
  const double phi = std::atan2(n.x, -n.z), theta = std::acos(std::clamp(n.y, -1.0, 1.0));
  return glm::vec2(float((phi + kPi) / (2.0 * kPi)), float(theta / kPi));
}

CubeMap cube_from_equirect(int width, int height, const std::vector<glm::vec3>& rgb, int size, float rotation_deg,
                           int supersampling) {
  check_size(size);
  if (width < 2 || height < 1 || rgb.size() != std::size_t(width) * std::size_t(height))
    throw ProbeError(fmt::format("equirectangular image of {}x{} with {} texels", width, height, rgb.size()));
  const auto fetch = [&](int x, int y) {
    x = ((x % width) + width) % width;
    y = std::clamp(y, 0, height - 1);
    return rgb[std::size_t(y) * width + x];
  };
  const double rotation = glm::radians(double(rotation_deg));
  const float c = float(std::cos(rotation)), s = float(std::sin(rotation));
  CubeMap cube;
  cube.size = size;
  const int ss = std::max(supersampling, 1);
  for (int face = 0; face < 6; ++face) {
    cube.faces[face].resize(std::size_t(size) * size);
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) {
        glm::vec3 sum(0.0f);
        for (int b = 0; b < ss; ++b)
          for (int a = 0; a < ss; ++a) {
            const float u = face_coordinate(i, size, (a + 0.5f) / ss), v = face_coordinate(j, size, (b + 0.5f) / ss);
            const glm::vec3 d = msm_cube_direction(face, u, v);
            // The probe turned by +rotation about +Y: look the direction up turned by −rotation.
            const glm::vec3 local(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
            const glm::vec2 st = equirect_of(local);
            const float x = st.x * float(width) - 0.5f, y = st.y * float(height) - 0.5f;
            const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
            const float fx = x - float(x0), fy = y - float(y0);
            sum += (1 - fy) * ((1 - fx) * fetch(x0, y0) + fx * fetch(x0 + 1, y0)) +
                   fy * ((1 - fx) * fetch(x0, y0 + 1) + fx * fetch(x0 + 1, y0 + 1));
          }
        cube.at(face, i, j) = sum / float(ss * ss);
      }
  }
  return cube;
}

CubeMap load_equirect_probe(const std::filesystem::path& file, int size, float rotation_deg) {
  image::Image picture;
  try {
    picture = image::read_exr(file);
  } catch (const std::exception& e) {
    throw ProbeError(fmt::format("{}: cannot read the light probe: {}", file.string(), e.what()));
  }
  // Channels by name: EXR files list them alphabetically (B, G, R), whatever order they were written in.
  int index[3] = {-1, -1, -1};
  const std::vector<std::string>& names = picture.channel_names();
  for (int c = 0; c < int(names.size()); ++c)
    for (int k = 0; k < 3; ++k)
      if (names[c] == std::string(1, "RGB"[k])) index[k] = c;
  if (index[0] < 0 || index[1] < 0 || index[2] < 0)
    throw ProbeError(fmt::format("{}: a light probe needs channels R, G and B", file.string()));
  if (picture.width() != 2 * picture.height())
    throw ProbeError(fmt::format("{}: {}x{} is not an equirectangular panorama (width = 2 height)", file.string(),
                                 picture.width(), picture.height()));
  std::vector<glm::vec3> rgb(picture.pixel_count());
  const int n = picture.channels();
  const float* p = picture.pixels().data();
  for (std::size_t k = 0; k < rgb.size(); ++k, p += n) {
    const glm::vec3 value(p[index[0]], p[index[1]], p[index[2]]);
    if (!glm::all(glm::lessThan(glm::abs(value), glm::vec3(3e38f)))) // also NaN
      throw ProbeError(fmt::format("{}: texel ({}, {}) has a non-finite radiance", file.string(), k % picture.width(),
                                   k / picture.width()));
    // Lossy compression (DWAA/DWAB, as blender-data's probes use) rings slightly below zero next to
    // dark texels: no light is negative.
    rgb[k] = glm::max(value, glm::vec3(0.0f));
  }
  return cube_from_equirect(picture.width(), picture.height(), rgb, size, rotation_deg);
}

CubeMap make_sky_sun_probe(int size, glm::vec3 sky, glm::vec3 sun, glm::vec3 towards_sun, float sun_radius_rad) {
  check_size(size);
  const glm::vec3 axis = glm::normalize(towards_sun);
  const float cos_radius = std::cos(sun_radius_rad);
  const float texel_angle = 2.5f / float(size); // bounds a texel's angular half-diagonal
  CubeMap cube;
  cube.size = size;
  for (int face = 0; face < 6; ++face) {
    cube.faces[face].resize(std::size_t(size) * size);
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) {
        const glm::vec3 d =
            glm::normalize(msm_cube_direction(face, face_coordinate(i, size), face_coordinate(j, size)));
        const float angle = std::acos(std::clamp(glm::dot(d, axis), -1.0f, 1.0f));
        float covered;
        if (angle < sun_radius_rad - texel_angle) {
          covered = 1.0f;
        } else if (angle > sun_radius_rad + texel_angle) {
          covered = 0.0f;
        } else { // the disc's edge crosses the texel: the share of 16² point samples inside
          const int n = 16;
          int inside = 0;
          for (int b = 0; b < n; ++b)
            for (int a = 0; a < n; ++a) {
              const glm::vec3 ds = glm::normalize(msm_cube_direction(face, face_coordinate(i, size, (a + 0.5f) / n),
                                                                     face_coordinate(j, size, (b + 0.5f) / n)));
              inside += glm::dot(ds, axis) >= cos_radius;
            }
          covered = float(inside) / float(n * n);
        }
        cube.at(face, i, j) = sky + covered * (sun - sky);
      }
  }
  return cube;
}

glm::dvec3 integrate(const CubeMap& cube) {
  glm::dvec3 sum(0.0);
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < cube.size; ++j)
      for (int i = 0; i < cube.size; ++i)
        sum += double(msm_cube_texel_weight(face_coordinate(i, cube.size), face_coordinate(j, cube.size),
                                            float(cube.size))) *
               glm::dvec3(cube.at(face, i, j));
  return sum;
}

ProbeTables::ProbeTables(const CubeMap& cube) : size_(cube.size) {
  check_size(size_);
  const std::size_t stride = std::size_t(size_) + 1;
  for (int face = 0; face < 6; ++face) {
    for (auto& table : tables_[face]) table.assign(stride * stride, 0.0);
    for (int j = 0; j < size_; ++j)
      for (int i = 0; i < size_; ++i) {
        const float u = face_coordinate(i, size_), v = face_coordinate(j, size_);
        const double w = msm_cube_texel_weight(u, v, float(size_));
        const glm::dvec3 xyz = w * glm::dvec3(msm_rgb_to_xyz(cube.at(face, i, j)));
        const double values[7] = {xyz.x, xyz.y, xyz.z, xyz.y * u, xyz.y * v, xyz.y * u * u, xyz.y * v * v};
        for (int k = 0; k < 7; ++k) {
          auto& t = tables_[face][k];
          t[(j + 1) * stride + i + 1] = values[k] + t[j * stride + i + 1] + t[(j + 1) * stride + i] - t[j * stride + i];
        }
      }
  }
}

double ProbeTables::rect(int face, int k, const Region& r) const {
  const auto& t = tables_[face][k];
  const std::size_t stride = std::size_t(size_) + 1;
  return t[r.y1 * stride + r.x1] - t[r.y0 * stride + r.x1] - t[r.y1 * stride + r.x0] + t[r.y0 * stride + r.x0];
}

double ProbeTables::energy(const Region& r) const { return rect(r.face, 1, r); }

MsmRegionSums ProbeTables::sums(const Region& r) const {
  return MsmRegionSums(glm::vec3(float(rect(r.face, 0, r)), float(rect(r.face, 1, r)), float(rect(r.face, 2, r))),
                       glm::vec2(float(rect(r.face, 3, r)), float(rect(r.face, 4, r))),
                       glm::vec2(float(rect(r.face, 5, r)), float(rect(r.face, 6, r))));
}

std::vector<Region> median_cut(const ProbeTables& tables, int count) {
  if (count < 6 || count > 256)
    throw ProbeError(fmt::format("{} lights: the median cut makes 6 to 256 (one region per cube face at least; "
                                 "regions never straddle faces)",
                                 count));
  std::vector<Region> regions;
  for (int face = 0; face < 6; ++face) {
    Region r{face, 0, 0, tables.size(), tables.size()};
    r.energy = tables.energy(r);
    regions.push_back(r);
  }
  while (int(regions.size()) < count) {
    // The most energetic region that can be split (ties: the first, so the result is deterministic).
    int best = -1;
    for (int k = 0; k < int(regions.size()); ++k) {
      const Region& r = regions[k];
      if (r.x1 - r.x0 < 2 && r.y1 - r.y0 < 2) continue;
      if (best < 0 || r.energy > regions[best].energy) best = k;
    }
    if (best < 0) break; // every region is one texel
    const Region r = regions[best];
    const bool along_x = (r.x1 - r.x0) >= (r.y1 - r.y0);
    const int lo = along_x ? r.x0 : r.y0, hi = along_x ? r.x1 : r.y1;
    const auto first_part = [&](int cut) {
      Region a = r;
      (along_x ? a.x1 : a.y1) = cut;
      return a;
    };
    // The cut in (lo, hi) where the first part's energy is closest to half: the energy grows with
    // the cut, so a binary search finds the first cut reaching half, then its neighbour is compared.
    const double half = 0.5 * r.energy;
    int a = lo + 1, b = hi - 1;
    while (a < b) {
      const int mid = (a + b) / 2;
      if (tables.energy(first_part(mid)) < half)
        a = mid + 1;
      else
        b = mid;
    }
    int cut = a;
    if (cut - 1 > lo &&
        std::abs(tables.energy(first_part(cut - 1)) - half) <= std::abs(tables.energy(first_part(cut)) - half))
      cut -= 1;
    Region first = first_part(cut), second = r;
    (along_x ? second.x0 : second.y0) = cut;
    first.energy = tables.energy(first);
    second.energy = tables.energy(second);
    regions[best] = first;
    regions.push_back(second);
  }
  return regions;
}

std::vector<MsmAreaLight> area_lights(const ProbeTables& tables, const std::vector<Region>& regions) {
  std::vector<MsmAreaLight> lights;
  for (const Region& r : regions) {
    const MsmRegionSums s = tables.sums(r);
    if (!(s.xyz.y > 0.0f)) continue;
    lights.push_back(msm_area_light_from_region(r.face, s));
  }
  return lights;
}

CubeMap sky_probe(int size, float rotation_deg) {
  // The sun turned by +rotation about +Y (cube_from_equirect looks directions up turned by −rotation).
  const double r = glm::radians(double(rotation_deg));
  const float c = float(std::cos(r)), s = float(std::sin(r));
  const glm::vec3 sun(0.4f, 0.6f, -0.3f);
  return make_sky_sun_probe(size, glm::vec3(0.15f, 0.22f, 0.4f), glm::vec3(40000.0f, 36000.0f, 30000.0f),
                            glm::vec3(c * sun.x + s * sun.z, sun.y, -s * sun.x + c * sun.z), glm::radians(0.27f));
}

CubeMap load_probe(const std::string& probe, int size, float rotation_deg, float intensity) {
  CubeMap cube = probe == "sky" ? sky_probe(size, rotation_deg) : load_equirect_probe(probe, size, rotation_deg);
  for (auto& face : cube.faces)
    for (glm::vec3& t : face) t *= intensity;
  return cube;
}

std::vector<MsmAreaLight> probe_area_lights(const std::string& probe, int size, int count, float rotation_deg,
                                            float intensity) {
  const ProbeTables tables(load_probe(probe, size, rotation_deg, intensity));
  return area_lights(tables, median_cut(tables, count));
}

} // namespace msm::probe
