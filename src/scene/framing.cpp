// The shadow map's framing ("fit": what the camera sees) and the checks that its texels are not
// too coarse for the image and that an explicit one holds what matters (shadow_framing_warnings).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <glm/ext/matrix_clip_space.hpp>

#include "msm/scene/scene.h"

namespace msm::scene {
namespace {

// A plane n . p + d >= 0 (inside).
struct Plane {
  glm::dvec3 n;
  double d;
  double at(const glm::dvec3& p) const { return glm::dot(n, p) + d; }
};

struct Edge {
  glm::dvec3 a, b;
};

// A convex polyhedron given by its corners, edges and inward planes (a box or a frustum).
struct Hull {
  std::vector<glm::dvec3> corners;
  std::vector<Edge> edges;
  std::vector<Plane> planes;
  bool contains(const glm::dvec3& p, double tolerance) const {
    for (const Plane& plane : planes)
      if (plane.at(p) < -tolerance) return false;
    return true;
  }
};

// The 8 corners (index bit 0: x, bit 1: y, bit 2: z) of a box-like solid, their 12 edges and its
// 6 inward planes.
Hull hull_of_corners(const std::array<glm::dvec3, 8>& c) {
  Hull h;
  h.corners.assign(c.begin(), c.end());
  for (int i = 0; i < 8; ++i)
    for (int bit = 1; bit < 8; bit <<= 1)
      if (!(i & bit)) h.edges.push_back({c[i], c[i | bit]});
  const glm::dvec3 centre = 0.125 * (c[0] + c[1] + c[2] + c[3] + c[4] + c[5] + c[6] + c[7]);
  // Each face: the 4 corners with one index bit fixed; its plane from three of them.
  for (int bit = 1; bit < 8; bit <<= 1)
    for (int value : {0, bit}) {
      std::vector<glm::dvec3> face;
      for (int i = 0; i < 8; ++i)
        if ((i & bit) == value) face.push_back(c[i]);
      glm::dvec3 n = glm::cross(face[1] - face[0], face[2] - face[0]);
      if (glm::length(n) == 0.0) n = glm::cross(face[3] - face[0], face[2] - face[0]);
      n = glm::normalize(n);
      Plane p{n, -glm::dot(n, face[0])};
      if (p.at(centre) < 0.0) p = {-n, -p.d};
      h.planes.push_back(p);
    }
  return h;
}

// Corners of the intersection of two convex hulls: the corners of each inside the other and the
// points where an edge of one crosses a face plane of the other inside both.
std::vector<glm::dvec3> intersection_corners(const Hull& a, const Hull& b, double tolerance) {
  std::vector<glm::dvec3> out;
  for (const auto& [one, other] : {std::pair{&a, &b}, std::pair{&b, &a}}) {
    for (const glm::dvec3& p : one->corners)
      if (other->contains(p, tolerance)) out.push_back(p);
    for (const Edge& e : one->edges)
      for (const Plane& plane : other->planes) {
        const double da = plane.at(e.a), db = plane.at(e.b);
        if ((da < 0.0) == (db < 0.0) || da == db) continue;
        const glm::dvec3 p = e.a + (da / (da - db)) * (e.b - e.a);
        if (a.contains(p, tolerance) && b.contains(p, tolerance)) out.push_back(p);
      }
  }
  return out;
}

// The camera's view frustum for the widest image the fit serves (kFitMaxAspect).
Hull camera_frustum(const Camera& camera) {
  const glm::dmat4 inv = glm::inverse(glm::dmat4(camera.projection(kFitMaxAspect)) * glm::dmat4(camera.view()));
  std::array<glm::dvec3, 8> c;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec4 q = inv * glm::dvec4(i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : 0.0, 1.0);
    c[i] = glm::dvec3(q) / q.w;
  }
  return hull_of_corners(c);
}

Hull box_hull(const Bounds& b) {
  std::array<glm::dvec3, 8> c;
  for (int i = 0; i < 8; ++i)
    c[i] = glm::dvec3(i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z);
  return hull_of_corners(c);
}

} // namespace

LightBox fit_light_frustum(const Scene& scene, const glm::mat4& light_view, bool visible_only) {
  const Bounds b = scene.bounds();
  LightBox box;
  if (b.empty()) return box;
  const glm::dmat4 v(light_view);
  const double size = glm::length(glm::dvec3(b.size()));
  // A tiny margin keeps rounding from pushing points out; depth 0 stays at the closest point.
  const double margin = 1e-5 * size + 1e-6;
  auto extend = [](glm::dvec3& l, glm::dvec3& h, const glm::dvec3& p) {
    l = glm::min(l, p);
    h = glm::max(h, p);
  };
  // Every vertex (tighter than the bounds' corners): near plane at the closest to the light, far
  // plane at the farthest.
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const Object& o : scene.objects)
    for (const glm::vec3& q : o.mesh.positions) extend(lo, hi, glm::dvec3(v * glm::dvec4(glm::dvec3(q), 1.0)));
  if (visible_only) {
    // A flat scene (a plane) has a zero-thickness box: give it the margin so the planes exist.
    Bounds grown = b;
    grown.extend(b.min - glm::vec3(float(margin)));
    grown.extend(b.max + glm::vec3(float(margin)));
    glm::dvec3 vlo(1e300), vhi(-1e300);
    for (const glm::dvec3& p : intersection_corners(camera_frustum(scene.camera), box_hull(grown), 1e-9 * size))
      extend(vlo, vhi, glm::dvec3(v * glm::dvec4(p, 1.0)));
    // The bounds' box holds empty space (its corners stick out of the geometry in light space):
    // the visible part is also within the vertices' box.
    vlo = glm::max(vlo, lo);
    vhi = glm::min(vhi, hi);
    box.visible_only = vlo.x <= vhi.x && vlo.y <= vhi.y && vlo.z <= vhi.z;
    if (box.visible_only) {
      // Casters: every vertex over the fitted rectangle may shadow it, so the near plane moves up
      // to the closest of them (view space looks down -z: nearer the light = larger z).
      for (const Object& o : scene.objects)
        for (const glm::vec3& q : o.mesh.positions) {
          const glm::dvec3 p(v * glm::dvec4(glm::dvec3(q), 1.0));
          if (p.x >= vlo.x - margin && p.x <= vhi.x + margin && p.y >= vlo.y - margin && p.y <= vhi.y + margin)
            vhi.z = std::max(vhi.z, p.z);
        }
      lo = vlo;
      hi = vhi;
    }
  }
  lo -= margin;
  hi += margin;
  box.lo = glm::vec3(lo);
  box.hi = glm::vec3(hi);
  return box;
}

namespace {

// Sutherland–Hodgman: the part of the convex polygon where inside(p) >= 0 (a linear function).
template <class Inside>
void clip_polygon(std::vector<glm::dvec4>& poly, std::vector<glm::dvec4>& scratch, Inside inside) {
  scratch.clear();
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec4 &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double da = inside(a), db = inside(b);
    if (da >= 0.0) scratch.push_back(a);
    if ((da >= 0.0) != (db >= 0.0)) scratch.push_back(a + (da / (da - db)) * (b - a));
  }
  poly.swap(scratch);
}

// Clips a clip-space polygon to -w <= x, y <= w and z <= w, and with `near` to z >= 0 as well
// (Vulkan's depth range).
void clip_to_box(std::vector<glm::dvec4>& poly, std::vector<glm::dvec4>& scratch, bool near) {
  for (int plane = 0; plane < 6 && !poly.empty(); ++plane) {
    if (plane == 4 && !near) continue;
    clip_polygon(poly, scratch, [plane](const glm::dvec4& p) {
      switch (plane) {
      case 0: return p.w + p.x;
      case 1: return p.w - p.x;
      case 2: return p.w + p.y;
      case 3: return p.w - p.y;
      case 4: return p.z;
      default: return p.w - p.z;
      }
    });
  }
}

} // namespace

TexelCoverage shadow_texel_coverage(const Scene& scene, int width, int height, int shadow_size,
                                    const CascadeOptions& cascades) {
  TexelCoverage c;
  // The orthographic map of the first directional light; spot and point lights alone have none.
  if (width <= 0 || height <= 0 || shadow_size <= 0 || scene.lights.empty()) return c;
  const glm::dmat4 camera_vp =
      glm::dmat4(scene.camera.projection(float(width) / float(height))) * glm::dmat4(scene.camera.view());
  const glm::dmat4 light_vp(scene.light_view_projection());
  // One texel in world units: the orthographic box's width and height over the map's texels.
  const glm::dmat4 light_inv = glm::inverse(light_vp);
  c.texel_size = 2.0 * std::max(glm::length(glm::dvec3(light_inv[0])), glm::length(glm::dvec3(light_inv[1]))) /
                 double(shadow_size);
  // The nearest surface inside the view frustum: clip each triangle to it in clip space (w is the
  // view depth) and keep the smallest w of the clipped polygon. Surfaces hidden behind others count
  // too: the bound is meant for the closest surface the camera shows, which is never hidden.
  const glm::dmat4 camera_inverse = glm::inverse(camera_vp);
  double nearest = std::numeric_limits<double>::infinity();
  glm::dvec3 nearest_point(0.0);
  std::vector<glm::dvec4> poly, next;
  for (const Object& o : scene.objects) {
    const Mesh& m = o.mesh;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      poly.clear();
      for (int k = 0; k < 3; ++k)
        poly.push_back(camera_vp * glm::dvec4(glm::dvec3(m.positions[m.indices[3 * t + std::size_t(k)]]), 1.0));
      clip_to_box(poly, next, true);
      for (const glm::dvec4& p : poly)
        if (p.w < nearest) {
          nearest = p.w;
          const glm::dvec4 world = camera_inverse * p;
          nearest_point = glm::dvec3(world) / world.w;
        }
    }
  }
  if (!std::isfinite(nearest)) return c; // the camera sees nothing
  c.visible = true;
  c.distance = nearest;
  c.where = glm::vec3(nearest_point);
  // Pixels per world unit across the view direction at view depth w: height / (2 w tan(fov/2)).
  const double pixels_per_unit =
      double(height) / (2.0 * nearest * std::tan(double(scene.camera.fov_y_deg) * std::numbers::pi / 360.0));
  if (cascades.count > 1 && scene.shadow.mode == ShadowFraming::Mode::fit) {
    // The cascade that shades the nearest surface (the first whose slice reaches it).
    for (const Cascade& k : fit_cascades(scene, scene.light(), shadow_size, cascades)) {
      const glm::dvec2 texel = k.frame.texel(shadow_size);
      c.texel_size = std::max(texel.x, texel.y);
      if (nearest <= k.fade_out.y) break;
    }
  }
  c.pixels_per_texel = c.texel_size * pixels_per_unit;
  c.aspect_beyond_fit = scene.shadow.mode == ShadowFraming::Mode::fit && double(width) / height > kFitMaxAspect;
  return c;
}

namespace {

// Whether the triangle's part selected by `clip` (world points, w = 1) meets the light's map box:
// clip-space x and y in [-1, 1] and depth at most 1 (orthographic: w stays 1).
template <class Clip>
bool meets_map(const glm::dmat4& light_vp, std::array<glm::dvec4, 3> triangle, Clip clip, std::vector<glm::dvec4>& poly,
               std::vector<glm::dvec4>& scratch) {
  poly.assign(triangle.begin(), triangle.end());
  clip(poly, scratch);
  for (glm::dvec4& p : poly) p = light_vp * p;
  clip_to_box(poly, scratch, false);
  return !poly.empty();
}

} // namespace

std::vector<FramingMiss> shadow_framing_misses(const Scene& scene, int width, int height) {
  std::vector<FramingMiss> misses;
  if (scene.shadow.mode != ShadowFraming::Mode::given || width <= 0 || height <= 0) return misses;
  const glm::dmat4 camera_vp =
      glm::dmat4(scene.camera.projection(float(width) / float(height))) * glm::dmat4(scene.camera.view());
  const glm::dmat4 camera_inverse = glm::inverse(camera_vp);
  // The part of a triangle inside the camera's view frustum, back in world space (w = 1).
  const auto visible_part = [&](std::vector<glm::dvec4>& poly, std::vector<glm::dvec4>& scratch) {
    for (glm::dvec4& p : poly) p = camera_vp * p;
    clip_to_box(poly, scratch, true);
    for (glm::dvec4& p : poly) {
      p = camera_inverse * p;
      p /= p.w;
    }
  };
  const auto whole = [](std::vector<glm::dvec4>&, std::vector<glm::dvec4>&) {};
  std::vector<glm::dvec4> poly, scratch;
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const glm::dmat4 light_vp(scene.light_view_projection(l));
    bool receiver = false, caster = false;
    for (const Object& o : scene.objects) {
      const Mesh& m = o.mesh;
      for (std::size_t t = 0; t < m.triangle_count() && !(receiver && caster); ++t) {
        std::array<glm::dvec4, 3> triangle;
        for (int k = 0; k < 3; ++k)
          triangle[std::size_t(k)] = glm::dvec4(glm::dvec3(m.positions[m.indices[3 * t + std::size_t(k)]]), 1.0);
        if (!caster) caster = meets_map(light_vp, triangle, whole, poly, scratch);
        if (!receiver) receiver = meets_map(light_vp, triangle, visible_part, poly, scratch);
      }
    }
    if (!receiver || !caster) misses.push_back({l, !receiver, !caster});
  }
  return misses;
}

std::vector<std::string> shadow_framing_warnings(const Scene& scene, int width, int height, int shadow_size,
                                                 const CascadeOptions& cascades) {
  std::vector<std::string> out;
  const TexelCoverage c = shadow_texel_coverage(scene, width, height, shadow_size, cascades);
  if (c.pixels_per_texel > kMaxPixelsPerTexel) {
    const int needed = int(std::min<double>(65536.0, std::ceil(shadow_size * c.pixels_per_texel / kMaxPixelsPerTexel)));
    const bool fit = scene.shadow.mode == ShadowFraming::Mode::fit;
    const std::string more_cascades =
        !fit ? "cascaded shadow maps (\"framing\": \"fit\", the default, and --cascades 4)"
        : cascades.count < kMaxCascades
            ? fmt::format("more cascades (--cascades {}; a larger --cascade-lambda puts more of them near)",
                          std::max(4, std::min(kMaxCascades, 2 * cascades.count)))
            : "a larger --cascade-lambda (the nearest cascade smaller)";
    out.push_back(fmt::format(
        "warning: one shadow-map texel ({:.3g} scene units{}) spans {:.1f} screen pixels (more than {:g}) at the "
        "nearest visible surface, {:.3g} units from the camera: shadows there are blocky or lost. Cures: a larger map "
        "(--shadow-size {} or more), {} in msm render, an explicit framing of what matters (\"shadow_map\": "
        "{{\"framing\": \"explicit\", ...}}), a camera that sees less of a large scene.",
        c.texel_size, cascades.count > 1 && fit ? fmt::format(", {} cascades", cascades.count) : std::string(),
        c.pixels_per_texel, kMaxPixelsPerTexel, c.distance, needed, more_cascades));
  }
  if (c.aspect_beyond_fit)
    out.push_back(fmt::format("warning: the image ({}x{}) is wider than the {:g}:1 the shadow map's fit covers: "
                              "surfaces at its left and right edges may lie outside the map (unshadowed). Cure: an "
                              "explicit framing.",
                              width, height, kFitMaxAspect));
  for (const FramingMiss& miss : shadow_framing_misses(scene, width, height)) {
    const ShadowFraming& f = scene.shadow;
    const std::string what = miss.receivers && miss.casters ? "none of the visible surfaces and no shadow caster"
                             : miss.receivers               ? "none of the visible surfaces"
                                                            : "no shadow caster";
    out.push_back(fmt::format(
        "warning: the explicit shadow-map framing (center [{:g}, {:g}, {:g}], extent [{:g}, {:g}], depth_range [{:g}, "
        "{:g}]) holds {} for light {}: it casts no shadow the camera can see. Cure: a framing around what the camera "
        "sees (\"shadow_map\": {{\"framing\": \"fit\"}}, the default).",
        f.center.x, f.center.y, f.center.z, f.extent.x, f.extent.y, f.depth_range.x, f.depth_range.y, what,
        miss.light));
  }
  return out;
}

std::optional<std::string> shadow_framing_warning(const Scene& scene, int width, int height, int shadow_size,
                                                  const CascadeOptions& cascades) {
  const std::vector<std::string> warnings = shadow_framing_warnings(scene, width, height, shadow_size, cascades);
  if (warnings.empty()) return std::nullopt;
  std::string text = warnings.front();
  for (std::size_t i = 1; i < warnings.size(); ++i) text += "\n" + warnings[i];
  return text;
}

} // namespace msm::scene

namespace msm::scene {

LightFrame orthographic_light_frame(const glm::mat4& view_projection, const glm::vec3& towards_light) {
  LightFrame f;
  f.view_projection = view_projection;
  const glm::dmat4 inv = glm::inverse(glm::dmat4(view_projection));
  f.towards_light = glm::normalize(glm::dvec3(towards_light));
  // Orthographic: a unit step of clip x (y, z) moves by inv[0] (inv[1], inv[2]) in world space.
  const glm::dvec3 cx(inv[0]), cy(inv[1]), cz(inv[2]);
  f.extent = {2.0 * glm::length(cx), 2.0 * glm::length(cy)};
  f.x_axis = glm::normalize(cx);
  f.y_axis = glm::normalize(cy);
  f.depth_extent = glm::length(cz);
  return f;
}

std::vector<double> cascade_splits(double near, double far, int count, double lambda) {
  std::vector<double> splits(std::size_t(count) + 1);
  for (int i = 0; i <= count; ++i) {
    const double t = double(i) / double(count);
    splits[std::size_t(i)] = lambda * near * std::pow(far / near, t) + (1.0 - lambda) * (near + (far - near) * t);
  }
  splits.front() = near;
  splits.back() = far;
  return splits;
}

glm::dvec2 visible_depth_range(const Scene& scene) {
  const Camera& camera = scene.camera;
  const glm::dvec2 planes(camera.near, camera.far);
  const Bounds b = scene.bounds();
  if (b.empty()) return planes;
  const double size = glm::length(glm::dvec3(b.size()));
  const float margin = float(1e-5 * size + 1e-6);
  Bounds grown = b;
  grown.extend(b.min - glm::vec3(margin));
  grown.extend(b.max + glm::vec3(margin));
  const std::vector<glm::dvec3> corners = intersection_corners(camera_frustum(camera), box_hull(grown), 1e-9 * size);
  if (corners.empty()) return planes;
  const glm::dmat4 view(camera.view());
  glm::dvec2 range(std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity());
  for (const glm::dvec3& p : corners) {
    const double depth = -(view * glm::dvec4(p, 1.0)).z; // view space looks down -z
    range = {std::min(range.x, depth), std::max(range.y, depth)};
  }
  range = glm::clamp(range, planes.x, planes.y);
  if (!(range.y > range.x)) range.y = std::min(planes.y, range.x * (1.0 + 1e-3) + 1e-6);
  return range;
}

namespace {

// The radius rounded up to 1/16 of the power of two below it: the same for every camera pose (the
// slice's shape does not move with the camera; rounding absorbs the float noise of its corners).
double stable_radius(double radius) {
  const double step = std::exp2(std::floor(std::log2(radius)) - 4.0);
  return std::ceil(radius / step) * step;
}

// The orthographic map of one cascade: the light's view, its box around the bounding sphere of
// the slice corners (light view space), the casters over it moving the near plane up.
glm::mat4 cascade_view_projection(const Scene& scene, const glm::dmat4& light_view,
                                  const std::array<glm::dvec3, 8>& slice, int shadow_size, bool stabilize) {
  glm::dvec3 centre(0.0);
  for (const glm::dvec3& p : slice) centre += 0.125 * p;
  double radius = 0.0;
  for (const glm::dvec3& p : slice) radius = std::max(radius, glm::length(p - centre));
  radius = std::max(radius, 1e-6);
  glm::dvec3 c(light_view * glm::dvec4(centre, 1.0));
  if (stabilize) {
    radius = stable_radius(radius);
    const double texel = 2.0 * radius / double(shadow_size);
    c.x = std::round(c.x / texel) * texel;
    c.y = std::round(c.y / texel) * texel;
  }
  glm::dvec3 lo = c - radius, hi = c + radius;
  // Casters over the box nearer the light than the sphere (view space looks down -z: nearer the
  // light = larger z) move its near plane up to them; nearer ones still are clamped to depth 0.
  for (const Object& o : scene.objects)
    for (const glm::vec3& q : o.mesh.positions) {
      const glm::dvec3 p(light_view * glm::dvec4(glm::dvec3(q), 1.0));
      if (p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y) hi.z = std::max(hi.z, p.z);
    }
  const double margin = 1e-5 * radius;
  lo.z -= margin;
  hi.z += margin;
  glm::mat4 flip(1.0f);
  flip[1][1] = -1.0f; // Vulkan's clip y points down
  return flip * glm::orthoRH_ZO(float(lo.x), float(hi.x), float(lo.y), float(hi.y), float(-hi.z), float(-lo.z)) *
         glm::mat4(light_view);
}

// The view depths the cascades split: the given range (a depth buffer's) or the scene's estimate,
// within the camera's planes and never empty (a flat view of one depth still gets slices).
glm::dvec2 split_range(const Scene& scene, const CascadeOptions& options) {
  if (!options.depth_range) return visible_depth_range(scene);
  const glm::dvec2 planes(scene.camera.near, scene.camera.far);
  glm::dvec2 range = glm::clamp(*options.depth_range, planes.x, planes.y);
  if (!(range.y > range.x)) range.y = std::min(planes.y, range.x * (1.0 + 1e-3) + 1e-6);
  return range;
}

} // namespace

std::vector<Cascade> fit_cascades(const Scene& scene, const DirectionalLight& light, int shadow_size,
                                  const CascadeOptions& options) {
  const int count = std::clamp(options.count, 1, kMaxCascades);
  const glm::dvec2 range = split_range(scene, options);
  const std::vector<double> splits = cascade_splits(range.x, range.y, count, options.lambda);
  // The camera frustum's corners (bit 2: the far plane); view depth is linear along its edges.
  const Hull frustum = camera_frustum(scene.camera);
  const double near = scene.camera.near, far = scene.camera.far;
  const auto corners_at = [&](double depth, std::array<glm::dvec3, 8>& out, int far_bit) {
    const double t = (depth - near) / (far - near);
    for (int i = 0; i < 4; ++i)
      out[std::size_t(i | far_bit)] =
          frustum.corners[std::size_t(i)] + t * (frustum.corners[std::size_t(i | 4)] - frustum.corners[std::size_t(i)]);
  };
  const glm::dmat4 light_view(scene.light_view(light));
  std::vector<Cascade> cascades(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    Cascade& cascade = cascades[std::size_t(i)];
    const double start = splits[std::size_t(i)], end = splits[std::size_t(i) + 1];
    if (i > 0) {
      const double previous = options.blend * (start - splits[std::size_t(i) - 1]);
      cascade.fade_in = {start - previous, start};
    }
    if (i + 1 < count) cascade.fade_out = {end - options.blend * (end - start), end};
    std::array<glm::dvec3, 8> slice;
    corners_at(i > 0 ? cascade.fade_in.x : start, slice, 0);
    corners_at(end, slice, 4);
    cascade.frame = orthographic_light_frame(
        cascade_view_projection(scene, light_view, slice, shadow_size, options.stabilize), light.towards_light);
  }
  return cascades;
}

} // namespace msm::scene
