// Light probes on the CPU: equirectangular resampling, the procedural sky, summed-area tables
// and the median cut (include/msm/probe/probe.h).
#include "msm/probe/probe.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "msm/image/io.h"

namespace msm::probe {
namespace {

constexpr double kPi = 3.14159265358979323846;

float face_coordinate(int i, int size, float offset = 0.5f) { return msm_cube_face_coordinate(i, offset, float(size)); }

void check_size(int size) {
  if (size < 1 || size > kMaxCubeSize)
    throw ProbeError(fmt::format("cube map size {} outside 1..{}", size, kMaxCubeSize));
}

} // namespace

glm::vec2 rotation_cos_sin(float rotation_deg) {
  const double rotation = glm::radians(double(rotation_deg));
  return glm::vec2(float(std::cos(rotation)), float(std::sin(rotation)));
}

std::vector<float> texel_weights(int size) {
  check_size(size);
  std::vector<float> w(std::size_t(size) * size);
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i)
      w[std::size_t(j) * size + i] =
          msm_cube_texel_weight(face_coordinate(i, size), face_coordinate(j, size), float(size));
  return w;
}

std::vector<float> face_coordinates(int size) {
  check_size(size);
  std::vector<float> c(static_cast<std::size_t>(size));
  for (int i = 0; i < size; ++i) c[i] = face_coordinate(i, size);
  return c;
}

float table_scale(float max_component) {
  if (!(max_component > 0.0f)) return 1.0f;
  int e = 0;
  std::frexp(max_component, &e); // max_component < 2^e
  return std::ldexp(1.0f, std::clamp(60 - e, -100, 100));
}

glm::vec3 direction_of_equirect(glm::vec2 st) {
  const double phi = 2.0 * kPi * st.x - kPi, theta = kPi * st.y;
  return glm::vec3(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                   float(-std::sin(theta) * std::cos(phi)));
}

glm::vec2 equirect_of(glm::vec3 d) { return msm_equirect_of(d); }

CubeMap cube_from_equirect(int width, int height, const std::vector<glm::vec3>& rgb, int size, float rotation_deg,
                           int supersampling) {
  check_size(size);
  if (width < 2 || height < 1 || rgb.size() != std::size_t(width) * std::size_t(height))
    throw ProbeError(fmt::format("equirectangular image of {}x{} with {} texels", width, height, rgb.size()));
  const glm::ivec2 extent(width, height);
  const auto fetch = [&](glm::ivec2 p) {
    const glm::ivec2 q = msm_equirect_texel(p, extent);
    return rgb[std::size_t(q.y) * width + q.x];
  };
  const glm::vec2 cos_sin = rotation_cos_sin(rotation_deg);
  const int ss = std::max(supersampling, 1);
  return make_cube(size, [&](int face, int i, int j) {
    glm::vec3 sum(0.0f);
    for (int b = 0; b < ss; ++b)
      for (int a = 0; a < ss; ++a) {
        const float u = face_coordinate(i, size, (a + 0.5f) / ss), v = face_coordinate(j, size, (b + 0.5f) / ss);
        const glm::vec3 d = msm_probe_lookup_direction(msm_cube_direction(face, u, v), cos_sin);
        const MsmBilinearTap tap = msm_equirect_tap(msm_equirect_of(d), extent);
        sum += msm_bilinear(fetch(tap.p0), fetch(tap.p0 + glm::ivec2(1, 0)), fetch(tap.p0 + glm::ivec2(0, 1)),
                            fetch(tap.p0 + glm::ivec2(1, 1)), tap.f);
      }
    return sum / float(ss * ss);
  });
}

Panorama load_equirect(const std::filesystem::path& file) {
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
  std::vector<glm::vec3> rgb(picture.pixel_count());
  const int n = picture.channels();
  const float* p = picture.pixels().data();
  for (std::size_t k = 0; k < rgb.size(); ++k, p += n) {
    const glm::vec3 value(p[index[0]], p[index[1]], p[index[2]]);
    if (!(std::isfinite(value.x) && std::isfinite(value.y) && std::isfinite(value.z)))
      throw ProbeError(fmt::format("{}: texel ({}, {}) has a non-finite radiance", file.string(), k % picture.width(),
                                   k / picture.width()));
    const float largest = std::max({value.x, value.y, value.z});
    if (largest > kMaxProbeRadiance)
      throw ProbeError(fmt::format("{}: texel ({}, {}) has a radiance of {:g}, above the {:g} a probe may hold",
                                   file.string(), k % picture.width(), k / picture.width(), largest,
                                   kMaxProbeRadiance));
    // Lossy compression (DWAA/DWAB, as blender-data's probes use) rings slightly below zero next to
    // dark texels: no light is negative.
    rgb[k] = glm::max(value, glm::vec3(0.0f));
  }
  return Panorama{picture.width(), picture.height(), std::move(rgb)};
}

CubeMap load_equirect_probe(const std::filesystem::path& file, int size, float rotation_deg) {
  const Panorama p = load_equirect(file);
  return cube_from_equirect(p.width, p.height, p.rgb, size, rotation_deg);
}

namespace {

// (column, row) of each face's cell in the horizontal and the vertical cross.
constexpr int kHorizontalCells[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
constexpr int kVerticalCells[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {1, 3}};

// Picture texel of face texel (i, j) in a cross of faces of side m.
std::size_t cross_index(int face, int i, int j, int m, bool vertical) {
  const int(*cells)[2] = vertical ? kVerticalCells : kHorizontalCells;
  if (vertical && face == 5) i = m - 1 - i, j = m - 1 - j; // −Z turned by 180°
  const int width = (vertical ? 3 : 4) * m;
  return std::size_t(cells[face][1] * m + j) * std::size_t(width) + std::size_t(cells[face][0] * m + i);
}

} // namespace

CubeMap cube_from_cross(int width, int height, const std::vector<glm::vec3>& rgb) {
  if (rgb.size() != std::size_t(width) * std::size_t(height))
    throw ProbeError(fmt::format("cross image of {}x{} with {} texels", width, height, rgb.size()));
  const bool horizontal = width > 0 && width % 4 == 0 && 3 * (width / 4) == height;
  const bool vertical = height > 0 && height % 4 == 0 && 3 * (height / 4) == width;
  if (!horizontal && !vertical)
    throw ProbeError(
        fmt::format("{}x{} is not a cube-map cross (4s x 3s horizontal or 3s x 4s vertical)", width, height));
  const int size = horizontal ? width / 4 : height / 4;
  check_size(size);
  return make_cube(size, [&](int face, int i, int j) { return rgb[cross_index(face, i, j, size, vertical)]; });
}

std::vector<glm::vec3> cross_of_cube(const CubeMap& cube, bool vertical) {
  const int m = cube.size;
  std::vector<glm::vec3> rgb(std::size_t(12) * std::size_t(m) * std::size_t(m), glm::vec3(0.0f));
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) rgb[cross_index(face, i, j, m, vertical)] = cube.at(face, i, j);
  return rgb;
}

CubeMap cube_from_faces(const std::array<int, 6>& sizes, const std::array<std::vector<glm::vec3>, 6>& faces) {
  CubeMap cube;
  cube.size = sizes[0];
  check_size(cube.size);
  for (int face = 0; face < 6; ++face) {
    if (sizes[face] != cube.size || faces[face].size() != std::size_t(cube.size) * std::size_t(cube.size))
      throw ProbeError(
          fmt::format("cube face {} is not {}² like face 0 ({} texels)", face, cube.size, faces[face].size()));
    cube.faces[face] = faces[face];
  }
  return cube;
}

CubeMap downsample_cube(const CubeMap& cube, int size) {
  check_size(size);
  if (cube.size % size != 0)
    throw ProbeError(fmt::format("cube faces of {}² cannot be box-filtered to {}² (not a divisor)", cube.size, size));
  const int k = cube.size / size;
  return make_cube(size, [&](int face, int i, int j) {
    glm::dvec3 sum(0.0);
    for (int b = 0; b < k; ++b)
      for (int a = 0; a < k; ++a) sum += glm::dvec3(cube.at(face, i * k + a, j * k + b));
    return glm::vec3(sum / double(k * k));
  });
}

bool is_cube_faces_path(const std::filesystem::path& file) { return file.string().find("{face}") != std::string::npos; }

std::array<std::filesystem::path, 6> cube_face_files(const std::filesystem::path& pattern) {
  static constexpr const char* kNames[6] = {"px", "nx", "py", "ny", "pz", "nz"};
  std::array<std::filesystem::path, 6> files;
  for (int face = 0; face < 6; ++face) {
    std::string name = pattern.string();
    for (std::size_t at = name.find("{face}"); at != std::string::npos; at = name.find("{face}", at))
      name.replace(at, 6, kNames[face]);
    files[face] = name;
  }
  return files;
}

std::vector<std::filesystem::path> probe_input_files(const std::filesystem::path& file) {
  if (!is_cube_faces_path(file)) return {file};
  const std::array<std::filesystem::path, 6> faces = cube_face_files(file);
  return {faces.begin(), faces.end()};
}

void write_cube_faces(const std::filesystem::path& pattern, const CubeMap& cube) {
  if (!is_cube_faces_path(pattern))
    throw ProbeError(fmt::format("{}: six cube faces need a path with \"{{face}}\"", pattern.string()));
  const std::array<std::filesystem::path, 6> files = cube_face_files(pattern);
  std::array<std::filesystem::path, 6> temporary;
  try {
    for (int face = 0; face < 6; ++face) {
      msm::image::Image picture(cube.size, cube.size, std::vector<std::string>{"R", "G", "B"});
      for (std::size_t k = 0; k < cube.faces[face].size(); ++k)
        for (int c = 0; c < 3; ++c) picture.pixels()[3 * k + c] = cube.faces[face][k][c];
      temporary[face] = files[face];
      temporary[face] += ".partial.exr";
      msm::image::write_exr(temporary[face], picture);
    }
    for (int face = 0; face < 6; ++face) std::filesystem::rename(temporary[face], files[face]);
  } catch (const std::exception& e) {
    std::error_code ec;
    for (const std::filesystem::path& t : temporary)
      if (!t.empty()) std::filesystem::remove(t, ec);
    throw ProbeError(fmt::format("{}: writing the cube faces: {}", pattern.string(), e.what()));
  }
}

PictureLayout picture_layout(int width, int height) {
  if (width <= 0 || height <= 0) return PictureLayout::neither;
  if (width == 2 * height) return PictureLayout::panorama;
  if (4 * height == 3 * width || 4 * width == 3 * height) return PictureLayout::cross;
  return PictureLayout::neither;
}

CubeMap load_probe_file(const std::filesystem::path& file, int size, float rotation_deg) {
  check_size(size);
  if (is_cube_faces_path(file)) {
    if (rotation_deg != 0.0f)
      throw ProbeError(fmt::format("{}: six cube faces cannot be rotated (rotation {}°)", file.string(), rotation_deg));
    try {
      return load_cube_faces(cube_face_files(file), size);
    } catch (const ProbeError& e) { throw ProbeError(fmt::format("{}: {}", file.string(), e.what())); }
  }
  Panorama picture = load_equirect(file);
  const PictureLayout layout = picture_layout(picture.width, picture.height);
  if (layout == PictureLayout::panorama)
    return cube_from_equirect(picture.width, picture.height, picture.rgb, size, rotation_deg);
  if (layout == PictureLayout::neither)
    throw ProbeError(fmt::format("{}: {}x{} is neither an equirectangular panorama (width = 2 height) nor a cube-map "
                                 "cross (4:3 or 3:4)",
                                 file.string(), picture.width, picture.height));
  if (rotation_deg != 0.0f)
    throw ProbeError(fmt::format("{}: a cube-map cross cannot be rotated (rotation {}°)", file.string(), rotation_deg));
  try {
    return downsample_cube(cube_from_cross(picture.width, picture.height, picture.rgb), size);
  } catch (const ProbeError& e) { throw ProbeError(fmt::format("{}: {}", file.string(), e.what())); }
}

CubeMap load_cube_faces(const std::array<std::filesystem::path, 6>& files, int size) {
  std::array<int, 6> sizes{};
  std::array<std::vector<glm::vec3>, 6> faces;
  for (int face = 0; face < 6; ++face) {
    Panorama picture = load_equirect(files[face]);
    if (picture.width != picture.height)
      throw ProbeError(fmt::format("{}: a cube face must be square, not {}x{}", files[face].string(), picture.width,
                                   picture.height));
    sizes[face] = picture.width;
    faces[face] = std::move(picture.rgb);
  }
  return downsample_cube(cube_from_faces(sizes, faces), size);
}

CubeMap make_sky_sun_probe(int size, glm::vec3 sky, glm::vec3 sun, glm::vec3 towards_sun, float sun_radius_rad) {
  check_size(size);
  const glm::vec3 axis = glm::normalize(towards_sun);
  const float cos_radius = std::cos(sun_radius_rad);
  const float texel_angle = 2.5f / float(size); // bounds a texel's angular half-diagonal
  return make_cube(size, [&](int face, int i, int j) {
    const glm::vec3 d = glm::normalize(msm_cube_direction(face, face_coordinate(i, size), face_coordinate(j, size)));
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
    return sky + covered * (sun - sky);
  });
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

ProbeTables::ProbeTables(const CubeMap& cube, float scale) : size_(cube.size) {
  check_size(size_);
  if (scale <= 0.0f) {
    float largest = 0.0f;
    for (const auto& face : cube.faces)
      for (const glm::vec3& t : face) largest = std::max({largest, t.x, t.y, t.z});
    scale = table_scale(largest);
  }
  scale_ = scale;
  const std::vector<float> weights = texel_weights(size_), coordinates = face_coordinates(size_);
  const std::size_t stride = std::size_t(size_) + 1;
  for (int face = 0; face < 6; ++face) {
    for (auto& table : tables_[face]) table.assign(stride * stride, 0);
    for (int j = 0; j < size_; ++j)
      for (int i = 0; i < size_; ++i) {
        const MsmProbeTexel t = msm_probe_texel(cube.at(face, i, j), weights[std::size_t(j) * size_ + i],
                                                coordinates[i], coordinates[j], scale_);
        const float values[7] = {t.a.x, t.a.y, t.a.z, t.a.w, t.b.x, t.b.y, t.b.z};
        for (int k = 0; k < 7; ++k) {
          auto& s = tables_[face][k];
          // Wrapping arithmetic as on the device; the scale keeps true sums below 2^63.
          s[(j + 1) * stride + i + 1] =
              std::uint64_t(values[k]) + s[j * stride + i + 1] + s[(j + 1) * stride + i] - s[j * stride + i];
        }
      }
  }
}

std::uint64_t ProbeTables::rect(int face, int k, const Region& r) const {
  const auto& t = tables_[face][k];
  const std::size_t stride = std::size_t(size_) + 1;
  return t[r.y1 * stride + r.x1] - t[r.y0 * stride + r.x1] - t[r.y1 * stride + r.x0] + t[r.y0 * stride + r.x0];
}

std::vector<Region> region_parts(const Region& r, int size) {
  if (r.faces == 0) return {r};
  std::vector<Region> parts;
  for (int face = 0; face < 6; ++face)
    if (r.faces & (1u << face)) parts.push_back(Region{face, 0, 0, size, size});
  return parts;
}

std::uint64_t ProbeTables::fixed_energy(const Region& r) const {
  if (r.faces == 0) return rect(r.face, 1, r);
  std::uint64_t sum = 0; // six faces stay below 4π 2^60 < 2^64 (table_scale)
  for (const Region& part : region_parts(r, size_)) sum += rect(part.face, 1, part);
  return sum;
}

double ProbeTables::energy(const Region& r) const { return double(fixed_energy(r)) / double(scale_); }

MsmRegionSums ProbeTables::sums(const Region& r) const {
  const auto rect_float = [&](int k) { return float(rect(r.face, k, r)); };
  // The first moments come shifted by Σ w Y: the difference is taken in integers, then rounded.
  const std::int64_t y = std::int64_t(rect(r.face, 1, r));
  const glm::vec2 first(float(std::int64_t(rect(r.face, 3, r)) - y), float(std::int64_t(rect(r.face, 4, r)) - y));
  return msm_region_sums_from_fixed(glm::vec3(rect_float(0), rect_float(1), rect_float(2)), first,
                                    glm::vec2(rect_float(5), rect_float(6)), 1.0f / scale_);
}

namespace {

std::uint32_t face_mask(const Region& r) { return r.faces != 0 ? r.faces : 1u << r.face; }

// Some face of group a shares a cube edge with some face of group b: faces f and g do unless they
// are opposite (f / 2 == g / 2, the same axis).
bool share_an_edge(std::uint32_t a, std::uint32_t b) {
  for (int f = 0; f < 6; ++f)
    for (int g = 0; g < 6; ++g)
      if ((a & (1u << f)) && (b & (1u << g)) && f / 2 != g / 2) return true;
  return false;
}

// count < 6: the six face regions merged pairwise (median_cut's comment; probe_cut.comp does the same).
std::vector<Region> merge_faces(const ProbeTables& tables, std::vector<Region> regions, int count) {
  while (int(regions.size()) > count) {
    int best_i = -1, best_j = -1;
    std::uint64_t best = 0;
    for (int i = 0; i < int(regions.size()); ++i)
      for (int j = i + 1; j < int(regions.size()); ++j) {
        if (!share_an_edge(face_mask(regions[i]), face_mask(regions[j]))) continue;
        const std::uint64_t e = regions[i].fixed_energy + regions[j].fixed_energy;
        if (best_i < 0 || e < best) best_i = i, best_j = j, best = e;
      }
    // Two or more groups of faces always have a pair sharing an edge (only two single opposite faces
    // share none, and they are not all six).
    Region& merged = regions[best_i];
    merged.faces = face_mask(merged) | face_mask(regions[best_j]);
    merged.fixed_energy = best;
    merged.energy = double(best) / double(tables.scale());
    regions.erase(regions.begin() + best_j);
  }
  return regions;
}

} // namespace

void check_cut(int count, int size, bool horizon_split) {
  if (count < 1 || count > 256) throw ProbeError(fmt::format("{} lights: the median cut makes 1 to 256", count));
  if (!horizon_split) return;
  if (count < kHorizonSplitMinLights)
    throw ProbeError(fmt::format("{} lights: the horizon split starts from {} regions (the side faces' halves), so it "
                                 "makes {} to 256 lights",
                                 count, kHorizonSplitMinLights, kHorizonSplitMinLights));
  if (size % 2 != 0)
    throw ProbeError(
        fmt::format("cube faces of {}²: the horizon split halves the side faces, so the size must be even", size));
}

std::vector<Region> median_cut(const ProbeTables& tables, int count, bool horizon_split) {
  check_cut(count, tables.size(), horizon_split);
  std::vector<Region> regions;
  for (int k = 0; k < msm_first_region_count(horizon_split); ++k) {
    const MsmFirstRegion first = msm_first_region(k, tables.size(), horizon_split);
    Region r{first.face, first.rect.x, first.rect.y, first.rect.z, first.rect.w};
    r.fixed_energy = tables.fixed_energy(r);
    r.energy = tables.energy(r);
    regions.push_back(r);
  }
  if (count < 6) return merge_faces(tables, std::move(regions), count);
  while (int(regions.size()) < count) {
    // The most energetic region that can be split (ties: the first, so the result is deterministic).
    int best = -1;
    for (int k = 0; k < int(regions.size()); ++k) {
      const Region& r = regions[k];
      if (r.x1 - r.x0 < 2 && r.y1 - r.y0 < 2) continue;
      if (best < 0 || r.fixed_energy > regions[best].fixed_energy) best = k;
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
    // The cut in (lo, hi) where the first part's energy is closest to half (in integers: twice the
    // part against the whole, which stays below 2^63): the energy grows with the cut, so a binary
    // search finds the first cut reaching half, then its neighbour is compared (a tie: the lower
    // cut). probe_cut.comp does the same.
    const auto twice_minus_whole = [&](int cut) {
      return 2 * std::int64_t(tables.fixed_energy(first_part(cut))) - std::int64_t(r.fixed_energy);
    };
    int a = lo + 1, b = hi - 1;
    while (a < b) {
      const int mid = (a + b) / 2;
      if (twice_minus_whole(mid) < 0)
        a = mid + 1;
      else
        b = mid;
    }
    int cut = a;
    if (cut - 1 > lo && std::abs(twice_minus_whole(cut - 1)) <= std::abs(twice_minus_whole(cut))) cut -= 1;
    Region first = first_part(cut), second = r;
    (along_x ? second.x0 : second.y0) = cut;
    first.fixed_energy = tables.fixed_energy(first);
    second.fixed_energy = tables.fixed_energy(second);
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
    if (r.faces != 0) { // a group of faces
      MsmMergedSums s = msm_merged_sums_empty();
      for (const Region& part : region_parts(r, tables.size()))
        s = msm_merged_sums_add(s, part.face, tables.sums(part));
      if (s.xyz.y > 0.0f) lights.push_back(msm_area_light_from_merged(s));
      continue;
    }
    const MsmRegionSums s = tables.sums(r);
    if (!(s.xyz.y > 0.0f)) continue;
    lights.push_back(msm_area_light_from_region(r.face, s));
  }
  return lights;
}

std::vector<std::vector<int>> sub_regions(const std::vector<Region>& coarse, const std::vector<Region>& fine) {
  std::vector<std::vector<int>> inside(coarse.size());
  for (int j = 0; j < int(fine.size()); ++j) {
    const Region& f = fine[j];
    int found = -1, matches = 0;
    for (int k = 0; k < int(coarse.size()); ++k) {
      const Region& c = coarse[k];
      const bool contains = c.faces != 0 ? f.faces == 0 && (c.faces >> f.face & 1u) != 0
                                         : f.faces == 0 && f.face == c.face && f.x0 >= c.x0 && f.x1 <= c.x1 &&
                                               f.y0 >= c.y0 && f.y1 <= c.y1;
      if (contains) found = k, ++matches;
    }
    if (matches != 1)
      throw ProbeError(
          fmt::format("region {} of the finer cut lies in {} regions of the coarser cut, not one", j, matches));
    inside[std::size_t(found)].push_back(j);
  }
  return inside;
}

CutLights cut_lights(const ProbeTables& tables, int count, bool horizon_split) {
  CutLights cut;
  cut.regions = median_cut(tables, count, horizon_split);
  for (const Region& r : cut.regions) {
    const std::vector<MsmAreaLight> light = area_lights(tables, {r});
    cut.light_of_region.push_back(light.empty() ? -1 : int(cut.lights.size()));
    if (!light.empty()) cut.lights.push_back(light[0]);
  }
  return cut;
}

std::vector<ProbeLight> with_sub_lights(const CutLights& coarse, const CutLights& fine) {
  const std::vector<std::vector<int>> inside = sub_regions(coarse.regions, fine.regions);
  std::vector<ProbeLight> out;
  for (std::size_t k = 0; k < coarse.regions.size(); ++k) {
    const int light = coarse.light_of_region[k];
    if (light < 0) continue; // no energy: no light, as area_lights skips it
    ProbeLight pl{coarse.lights[std::size_t(light)], {}};
    for (int j : inside[k])
      if (const int sub = fine.light_of_region[std::size_t(j)]; sub >= 0)
        pl.sub_lights.push_back(fine.lights[std::size_t(sub)]);
    out.push_back(std::move(pl));
  }
  return out;
}

std::vector<ProbeLight> lights_with_sub_lights(const ProbeTables& tables, int count, int sub_count,
                                               bool horizon_split) {
  CutLights coarse = cut_lights(tables, count, horizon_split);
  if (sub_lights_refine(count, sub_count)) return with_sub_lights(coarse, cut_lights(tables, sub_count, horizon_split));
  std::vector<ProbeLight> out;
  for (MsmAreaLight& light : coarse.lights) out.push_back({light, {}});
  return out;
}

std::vector<ProbeLight> probe_lights_with_sub_lights(const std::string& probe, int size, int count, int sub_count,
                                                     float rotation_deg, float intensity, bool horizon_split) {
  check_cut(count, size, horizon_split); // before loading the probe
  check_cut(std::max(count, sub_count), size, horizon_split);
  return lights_with_sub_lights(ProbeTables(load_probe(probe, size, rotation_deg, intensity)), count, sub_count,
                                horizon_split);
}

CubeMap sky_probe(int size, float rotation_deg) {
  // Where cube_from_equirect shows the panorama's direction p: the direction that looks p up.
  const glm::vec2 inverse = rotation_cos_sin(-rotation_deg);
  return make_sky_sun_probe(size, glm::vec3(0.15f, 0.22f, 0.4f), glm::vec3(40000.0f, 36000.0f, 30000.0f),
                            msm_probe_lookup_direction(glm::vec3(0.4f, 0.6f, -0.3f), inverse), glm::radians(0.27f));
}

CubeMap load_probe(const std::string& probe, int size, float rotation_deg, float intensity) {
  CubeMap cube = probe == "sky" ? sky_probe(size, rotation_deg) : load_probe_file(probe, size, rotation_deg);
  float brightest = 0.0f;
  for (auto& face : cube.faces)
    for (glm::vec3& t : face) {
      t *= intensity;
      brightest = std::max({brightest, t.x, t.y, t.z});
    }
  if (!(brightest <= kMaxProbeRadiance))
    throw ProbeError(fmt::format("{}: a radiance of {:g} at intensity {:g}, above the {:g} a probe may hold", probe,
                                 brightest, intensity, kMaxProbeRadiance));
  return cube;
}

std::vector<MsmAreaLight> probe_area_lights(const std::string& probe, int size, int count, float rotation_deg,
                                            float intensity, bool horizon_split) {
  check_cut(count, size, horizon_split); // before loading the probe
  const ProbeTables tables(load_probe(probe, size, rotation_deg, intensity));
  return area_lights(tables, median_cut(tables, count, horizon_split));
}

} // namespace msm::probe
