// Built-in primitives: plane, box, sphere, cylinder, fence/railing, stair, torus knot, brick wall.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>

#include "internal.h"

namespace msm::scene {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

void check_size(const char* what, float v) {
  if (!std::isfinite(v) || v <= 0.0f || v > kMaxSize)
    throw SceneError("", what, fmt::format("must be finite, > 0 and <= {:g} (got {:g})", kMaxSize, v));
}

void check_count(const char* what, int v, int min) {
  if (v < min || v > kMaxSegments)
    throw SceneError("", what, fmt::format("must be in [{}, {}] (got {})", min, kMaxSegments, v));
}

void check_triangles(std::size_t n) {
  if (n > kMaxPrimitiveTriangles)
    throw SceneError("", "",
                     fmt::format("would have {} triangles, more than the cap of {}", n, kMaxPrimitiveTriangles));
}

std::uint32_t add_vertex(Mesh& m, glm::vec3 p, glm::vec3 n, glm::vec2 uv) {
  m.positions.push_back(p);
  m.normals.push_back(n);
  m.uvs.push_back(uv);
  return static_cast<std::uint32_t>(m.positions.size() - 1);
}

void add_tri(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  m.indices.insert(m.indices.end(), {a, b, c});
}

// A (nu+1) x (nv+1) vertex grid from f(i, j, p, n, uv); winding fixed from the normals.
template <class F>
void add_grid(Mesh& m, int nu, int nv, F&& f) {
  const std::size_t first_tri = m.triangle_count();
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      glm::vec3 p, n;
      glm::vec2 uv;
      f(i, j, p, n, uv);
      add_vertex(m, p, n, uv);
    }
  const auto row = static_cast<std::uint32_t>(nu + 1);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::uint32_t a = base + j * row + i, b = a + 1, c = a + row, d = c + 1;
      add_tri(m, a, b, d);
      add_tri(m, a, d, c);
    }
  detail::fix_winding(m, first_tri);
}

void add_box(Mesh& m, glm::vec3 lo, glm::vec3 hi) {
  const glm::vec3 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
  struct Face {
    glm::vec3 n, u, v;
  };
  static const Face faces[6] = {{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                                {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                                {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}}};
  static const glm::vec2 corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (const Face& f : faces) {
    const glm::vec3 pn = f.n * glm::dot(glm::abs(f.n), h);
    const glm::vec3 pu = f.u * glm::dot(glm::abs(f.u), h);
    const glm::vec3 pv = f.v * glm::dot(glm::abs(f.v), h);
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    // v runs down the face (against f.v, its "up"): the picture upright (uv convention in scene.h).
    for (const glm::vec2& k : corners)
      add_vertex(m, c + pn + k.x * pu + k.y * pv, f.n, glm::vec2(0.5f * (k.x + 1.0f), 0.5f * (1.0f - k.y)));
    add_tri(m, base, base + 1, base + 2);
    add_tri(m, base, base + 2, base + 3);
  }
}

} // namespace

namespace detail {

void fix_winding(Mesh& m, std::size_t first_triangle) {
  for (std::size_t t = first_triangle; t < m.triangle_count(); ++t) {
    std::uint32_t* i = &m.indices[3 * t];
    const glm::vec3 e = glm::cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]);
    const glm::vec3 n = m.normals[i[0]] + m.normals[i[1]] + m.normals[i[2]];
    if (glm::dot(e, n) < 0.0f) std::swap(i[1], i[2]);
  }
}

void finalize_mesh(Mesh& m, const std::string& where) {
  if (m.normals.size() != m.positions.size()) throw SceneError("", where, "normals missing");
  if (m.uvs.size() != m.positions.size()) m.uvs.resize(m.positions.size(), glm::vec2(0.0f));
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    const glm::vec3& p = m.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw SceneError("", where, fmt::format("vertex {} has a NaN or infinite position", v));
    glm::vec3& n = m.normals[v];
    const float len = glm::length(n);
    n = (std::isfinite(len) && len > 0.0f) ? n / len : glm::vec3(0.0f, 1.0f, 0.0f);
    glm::vec2& uv = m.uvs[v];
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
  }
  if (m.indices.size() % 3 != 0) throw SceneError("", where, "index count is not a multiple of 3");
  std::size_t kept = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t* i = &m.indices[3 * t];
    if (i[0] >= m.positions.size() || i[1] >= m.positions.size() || i[2] >= m.positions.size())
      throw SceneError("", where, fmt::format("triangle {} has an index out of range", t));
    const glm::dvec3 a(m.positions[i[0]]), b(m.positions[i[1]]), c(m.positions[i[2]]);
    const double cross = glm::length(glm::cross(b - a, c - a));
    const double edge2 = std::max({glm::dot(b - a, b - a), glm::dot(c - a, c - a), glm::dot(c - b, c - b)});
    if (!(cross > 1e-10 * edge2) || edge2 == 0.0) continue; // degenerate: dropped
    for (int k = 0; k < 3; ++k) m.indices[3 * kept + k] = i[k];
    ++kept;
  }
  m.indices.resize(3 * kept);
  if (kept == 0) throw SceneError("", where, "the mesh has no triangles with a non-zero area");
}

} // namespace detail

Mesh make_plane(glm::vec2 size, glm::ivec2 sub) {
  check_size("size", size.x);
  check_size("size", size.y);
  check_count("subdivisions", sub.x, 1);
  check_count("subdivisions", sub.y, 1);
  check_triangles(2ull * sub.x * sub.y);
  Mesh m;
  add_grid(m, sub.x, sub.y, [&](int i, int j, glm::vec3& p, glm::vec3& n, glm::vec2& uv) {
    uv = {float(i) / sub.x, float(j) / sub.y};
    p = {(uv.x - 0.5f) * size.x, 0.0f, (uv.y - 0.5f) * size.y};
    n = {0, 1, 0};
  });
  detail::finalize_mesh(m, "plane");
  return m;
}

Mesh make_box(glm::vec3 size) {
  check_size("size", size.x);
  check_size("size", size.y);
  check_size("size", size.z);
  Mesh m;
  add_box(m, -0.5f * size, 0.5f * size);
  detail::finalize_mesh(m, "box");
  return m;
}

Mesh make_sphere(float radius, int segments, int rings) {
  check_size("radius", radius);
  check_count("segments", segments, 3);
  check_count("rings", rings, 2);
  check_triangles(2ull * segments * rings);
  Mesh m;
  add_grid(m, segments, rings, [&](int i, int j, glm::vec3& p, glm::vec3& n, glm::vec2& uv) {
    const float phi = 2.0f * kPi * float(i % segments) / segments;
    const float theta = kPi * float(j) / rings;
    const float st = (j == 0 || j == rings) ? 0.0f : std::sin(theta);
    const float ct = j == 0 ? 1.0f : j == rings ? -1.0f : std::cos(theta);
    n = {st * std::cos(phi), ct, -st * std::sin(phi)};
    p = radius * n;
    uv = {float(i) / segments, float(j) / rings};
  });
  detail::finalize_mesh(m, "sphere"); // drops the degenerate half of each pole quad
  return m;
}

Mesh make_cylinder(float radius, float height, int segments, bool caps) {
  check_size("radius", radius);
  check_size("height", height);
  check_count("segments", segments, 3);
  check_triangles(4ull * segments);
  Mesh m;
  const float h = 0.5f * height;
  auto ring = [&](int i) {
    const float phi = 2.0f * kPi * float(i % segments) / segments;
    return glm::vec3(std::cos(phi), 0.0f, -std::sin(phi));
  };
  add_grid(m, segments, 1, [&](int i, int j, glm::vec3& p, glm::vec3& n, glm::vec2& uv) {
    n = ring(i);
    p = radius * n + glm::vec3(0.0f, j == 0 ? -h : h, 0.0f);
    uv = {float(i) / segments, float(1 - j)}; // v down: row 0 of the picture at the top
  });
  if (caps) {
    for (float side : {-1.0f, 1.0f}) {
      const std::size_t first = m.triangle_count();
      const glm::vec3 n(0.0f, side, 0.0f);
      const std::uint32_t c = add_vertex(m, {0.0f, side * h, 0.0f}, n, {0.5f, 0.5f});
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      for (int i = 0; i < segments; ++i) {
        const glm::vec3 d = ring(i);
        add_vertex(m, radius * d + glm::vec3(0.0f, side * h, 0.0f), n, 0.5f + 0.5f * glm::vec2(d.x, d.z));
      }
      for (int i = 0; i < segments; ++i) add_tri(m, c, base + i, base + (i + 1) % segments);
      detail::fix_winding(m, first);
    }
  }
  detail::finalize_mesh(m, "cylinder");
  return m;
}

Mesh make_fence(float length, float height, int bars, float bar_width, float bar_depth, int rails, float rail_height) {
  check_size("length", length);
  check_size("height", height);
  check_size("bar_width", bar_width);
  check_size("bar_depth", bar_depth);
  check_size("rail_height", rail_height);
  check_count("bars", bars, 1);
  if (rails < 0 || rails > kMaxSegments)
    throw SceneError("", "rails", fmt::format("must be in [0, {}] (got {})", kMaxSegments, rails));
  if (bar_width > length) throw SceneError("", "bar_width", "must not exceed length");
  if (rails > 0 && rail_height * rails > height)
    throw SceneError("", "rail_height", "rails * rail_height must not exceed height");
  Mesh m;
  const float hd = 0.5f * bar_depth;
  for (int i = 0; i < bars; ++i) {
    const float x = bars == 1 ? 0.0f : -0.5f * (length - bar_width) + i * (length - bar_width) / (bars - 1);
    add_box(m, {x - 0.5f * bar_width, 0.0f, -hd}, {x + 0.5f * bar_width, height, hd});
  }
  for (int k = 0; k < rails; ++k) {
    const float top = height * float(rails - k) / rails;
    add_box(m, {-0.5f * length, top - rail_height, -hd}, {0.5f * length, top, hd});
  }
  detail::finalize_mesh(m, "fence");
  return m;
}

Mesh make_stair(int steps, float width, float step_depth, float step_height) {
  check_count("steps", steps, 1);
  check_size("width", width);
  check_size("step_depth", step_depth);
  check_size("step_height", step_height);
  Mesh m;
  for (int i = 0; i < steps; ++i)
    add_box(m, {-0.5f * width, 0.0f, -(i + 1) * step_depth}, {0.5f * width, (i + 1) * step_height, -i * step_depth});
  detail::finalize_mesh(m, "stair");
  return m;
}

Mesh make_torus_knot(int p, int q, float radius, float tube_radius, int segments, int tube_segments) {
  if (p < 1 || p > 64) throw SceneError("", "p", fmt::format("must be in [1, 64] (got {})", p));
  if (q < 1 || q > 64) throw SceneError("", "q", fmt::format("must be in [1, 64] (got {})", q));
  check_size("radius", radius);
  check_size("tube_radius", tube_radius);
  check_count("segments", segments, 3);
  check_count("tube_segments", tube_segments, 3);
  check_triangles(2ull * segments * tube_segments);
  auto curve = [&](float u) {
    const float cs = std::cos(float(q) / p * u);
    return 0.5f * radius * glm::vec3((2.0f + cs) * std::cos(u), (2.0f + cs) * std::sin(u), std::sin(float(q) / p * u));
  };
  Mesh m;
  add_grid(m, tube_segments, segments, [&](int i, int j, glm::vec3& pos, glm::vec3& n, glm::vec2& uv) {
    const float u = float(j % segments) / segments * p * 2.0f * kPi;
    const glm::vec3 p1 = curve(u), p2 = curve(u + 0.01f);
    const glm::vec3 t = p2 - p1;
    glm::vec3 b = glm::normalize(glm::cross(t, p2 + p1));
    const glm::vec3 nn = glm::normalize(glm::cross(b, t));
    const float v = float(i % tube_segments) / tube_segments * 2.0f * kPi;
    n = -std::cos(v) * nn + std::sin(v) * b; // outward from the tube's centre line
    pos = p1 + tube_radius * n;
    uv = {float(i) / tube_segments, float(j) / segments};
  });
  detail::finalize_mesh(m, "torus_knot");
  return m;
}

Mesh make_brick_wall(int rows, int columns, float brick_length, float brick_height, float mortar, float relief,
                     float thickness) {
  check_count("rows", rows, 1);
  check_count("columns", columns, 1);
  check_size("brick_length", brick_length);
  check_size("brick_height", brick_height);
  check_size("mortar", mortar);
  check_size("relief", relief);
  check_size("thickness", thickness);
  // Half bricks at the ends of the offset rows are (brick_length - mortar) / 2 long: they must exist.
  if (mortar >= brick_length) throw SceneError("", "mortar", "must be smaller than brick_length");
  if (mortar >= brick_height) throw SceneError("", "mortar", "must be smaller than brick_height");
  const double length = double(columns) * (brick_length + mortar) + mortar;
  const double height = double(rows) * (brick_height + mortar) + mortar;
  if (length > kMaxSize || height > kMaxSize)
    throw SceneError("", "", fmt::format("the wall would be {:g} x {:g}, more than {:g}", length, height, kMaxSize));
  check_triangles(12ull * (std::size_t(rows) * (columns + 1) + 1));
  Mesh m;
  const float half = 0.5f * float(length), cell = brick_length + mortar;
  // The mortar: the wall's core, its front face at z = 0.
  add_box(m, {-half, 0.0f, -thickness}, {half, float(height), 0.0f});
  // The bricks reach half-way into the core, so that no brick face is coplanar with a core face
  // (coplanar faces would fight in depth buffers and confuse shadow rays).
  for (int r = 0; r < rows; ++r) {
    const float y0 = mortar + r * (brick_height + mortar);
    // Running bond: odd rows shifted by half a brick, cut to the wall at both ends.
    const float shift = (r % 2 == 1) ? 0.5f * cell : 0.0f;
    const int bricks = (r % 2 == 1) ? columns + 1 : columns;
    for (int i = 0; i < bricks; ++i) {
      const float x0 = std::max(-half + mortar + i * cell - shift, -half + mortar);
      const float x1 = std::min(-half + mortar + i * cell - shift + brick_length, half - mortar);
      add_box(m, {x0, y0, -0.5f * thickness}, {x1, y0 + brick_height, relief});
    }
  }
  detail::finalize_mesh(m, "brick_wall");
  return m;
}

double Mesh::area() const {
  double a = 0.0;
  for (std::size_t t = 0; t < triangle_count(); ++t) {
    const glm::dvec3 p0(positions[indices[3 * t]]), p1(positions[indices[3 * t + 1]]),
        p2(positions[indices[3 * t + 2]]);
    a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
  }
  return a;
}

Bounds Mesh::bounds() const {
  Bounds b;
  for (const glm::vec3& p : positions) b.extend(p);
  return b;
}

} // namespace msm::scene
