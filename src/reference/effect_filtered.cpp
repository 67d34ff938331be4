// filtered: what a filtered shadow map means, on any geometry: the PCF kernel over the light's
// shadow-map plane, each sampled light ray's visibility at the receiver's depth extrapolated along
// the renderer's receiver plane (within the plane's tolerance), surfaces turned away from the light
// in their own shadow (reference.h has the definition).
#include <cmath>

#include "internal.h"
#include "msm/cube_face.h"
#include "msm/render/frame.h"

namespace msm::reference::detail {

EffectResult effect_filtered(const EffectContext& ctx, const SurfaceHit& hit, Rng& rng) {
  // The receiver as the renderer shades it: the interpolated normal, turned towards the viewer.
  glm::dvec3 n = ctx.tracer.shading_normal(hit);
  if (glm::dot(hit.normal, hit.incoming) > 0.0) n = -n;
  const double n_dot_l = glm::dot(n, ctx.towards_light);
  if (!(n_dot_l > 0.0)) {
    EffectResult turned_away; // in its own shadow, decided without sampling
    turned_away.value = 0.0;
    turned_away.samples = 0;
    turned_away.rays = 0;
    return turned_away;
  }
  // The plane's depth per texel along the map's x and y ([0,1] depth: world distance along the
  // light's travel over the map's depth range), clamped as the renderer clamps it. The plane is
  // the hit triangle's, as the renderer's (its triangle_normal): either side gives the same slope.
  const glm::dvec3& g = hit.normal;
  const double gx = glm::dot(g, ctx.frame.x_axis), gy = glm::dot(g, ctx.frame.y_axis);
  const double g_dot_l = glm::dot(g, ctx.towards_light);
  const double limit = double(MSM_MAX_RECEIVER_DEPTH_SLOPE);
  const glm::dvec2 slope = std::abs(g_dot_l) > 1e-6
                               ? glm::clamp(glm::dvec2(gx * glm::length(ctx.texel_x), gy * glm::length(ctx.texel_y)) /
                                                (g_dot_l * ctx.frame.depth_extent),
                                            glm::dvec2(-limit), glm::dvec2(limit))
                               : glm::dvec2(0.0);
  const glm::dvec3 travel = -ctx.towards_light;
  const SampleSet set(ctx.settings.sampler, ctx.settings.samples);
  RunningStats stats;
  // The ray origins of a batch of samples first, then their rays: each sample's arithmetic is a
  // chain of dependent steps (two square roots), which the processor overlaps across the samples
  // of a batch but not across a call into Embree. The same random numbers in the same
  // order: the same rays as one sample at a time.
  glm::dvec3 origins[kSampleBatch];
  for (int first = 0; first < set.count(); first += kSampleBatch) {
    const int n = std::min(kSampleBatch, set.count() - first);
    for (int k = 0; k < n; ++k) {
      const glm::dvec2 u = set.point(first + k, rng);
      const glm::dvec2 o(ctx.kernel.sample(u.x), ctx.kernel.sample(u.y));
      const glm::dvec3 o_world = o.x * ctx.texel_x + o.y * ctx.texel_y;
      // The light ray through (x, y) + o at the plane's depth there; surfaces within the plane's
      // tolerance of that point are the receiver itself, so the ray starts beyond them.
      const glm::dvec3 q = hit.p + o_world + (glm::dot(slope, o) * ctx.frame.depth_extent) * travel;
      const double tolerance =
          kOffsetScale * std::max(hit.scale, point_scale(q)) + kReceiverPlaneTolerance * glm::length(o_world);
      origins[k] = q + tolerance * ctx.towards_light;
    }
    bool blocked[kSampleBatch];
    glm::dvec3 dirs[kSampleBatch];
    for (int k = 0; k < n; ++k) dirs[k] = ctx.towards_light;
    ctx.tracer.occluded(origins, dirs, n, blocked);
    for (int k = 0; k < n; ++k) stats.add(blocked[k] ? 0.0 : 1.0);
  }
  return monte_carlo_result(stats);
}

namespace {

// A local light's map about the receiver's direction: its axes (the map's plane at unit distance
// along `forward`, coordinates the tangents along `right` and `up`) and one texel in tangents.
struct LocalMap {
  glm::dvec3 forward{0.0}, right{0.0}, up{0.0};
  double texel = 0.0;
};

// A spot's perspective map over its outer cone (the renderer's spot_light_uniforms: a look-at
// along its direction, 2 tan(outer) / size per texel). A point light's cube face that holds the
// receiver's direction over its 90-degree part, 2 / size per texel, and the kernel continues on
// that face's plane past the seam: what the renderer's guard band approximates (its faces are a
// few texels wider, so its texel is g = msm_cube_face_half_width times this one; the ideal map is
// the one without a seam, whose texel does not depend on the technique's guard band).
LocalMap local_map(const scene::LocalLight& light, const glm::dvec3& from_light, int shadow_size) {
  LocalMap m;
  if (light.spot()) {
    m.forward = glm::normalize(glm::dvec3(light.direction));
    const glm::dvec3 up = std::abs(m.forward.y) > 0.99 ? glm::dvec3(0.0, 0.0, 1.0) : glm::dvec3(0.0, 1.0, 0.0);
    m.right = glm::normalize(glm::cross(m.forward, up));
    m.up = glm::cross(m.right, m.forward);
    m.texel = 2.0 * std::tan(glm::radians(double(light.outer_cone_deg))) / shadow_size;
    return m;
  }
  const int face = msm_cube_face(glm::vec3(from_light));
  m.forward = glm::dvec3(msm_cube_face_forward(face));
  m.up = glm::dvec3(msm_cube_face_up(face));
  m.right = glm::dvec3(msm_cube_face_right(face));
  m.texel = 2.0 / shadow_size;
  return m;
}

} // namespace

// The filtered effect's definition in a spot's or point light's own map. The kernel's offset o
// (texels) moves the light ray's point on the map's plane by o texels; the receiver's depth along
// that ray is where it meets the receiver's triangle's plane, the exact plane rather than the
// renderer's first-order extrapolation of the radial depth, which agrees with it to first order in
// o; like the renderer's, the plane's radial distance changes by at most
// MSM_MAX_RECEIVER_DEPTH_SLOPE × range per texel along each axis, which also bounds a plane the
// ray meets at grazing incidence or not at all. V_o: nothing between that point and the light
// (a segment, not a ray to infinity), beyond the receiver plane's tolerance as for directional.
EffectResult filtered_local_visibility(const EffectContext& ctx, const SurfaceHit& hit, const scene::LocalLight& light,
                                       Rng& rng) {
  const glm::dvec3& n = hit.normal; // the hit triangle's plane, as the renderer's (either side)
  const glm::dvec3 position(light.position), from_light = hit.p - position;
  const double r0 = glm::length(from_light);
  const LocalMap map = local_map(light, from_light, ctx.settings.shadow_size);
  const double along = glm::dot(from_light, map.forward);
  if (!(along > 0.0)) return EffectResult{}; // the light on the surface: lit, as the hard effect has it
  const glm::dvec2 uv0(glm::dot(from_light, map.right) / along, glm::dot(from_light, map.up) / along);
  const double plane = glm::dot(from_light, n); // the tangent plane: dot(x − position, n) = plane
  const double slope_limit = double(MSM_MAX_RECEIVER_DEPTH_SLOPE) * double(light.range);
  const SampleSet set(ctx.settings.sampler, ctx.settings.samples);
  RunningStats stats;
  for (int i = 0; i < set.count(); ++i) {
    const glm::dvec2 u = set.point(i, rng);
    const glm::dvec2 o(ctx.kernel.sample(u.x), ctx.kernel.sample(u.y));
    const glm::dvec2 uv = uv0 + o * map.texel;
    const glm::dvec3 d = glm::normalize(map.forward + uv.x * map.right + uv.y * map.up);
    const double reach = slope_limit * (std::abs(o.x) + std::abs(o.y));
    const double towards_plane = glm::dot(d, n);
    double r = towards_plane != 0.0 ? plane / towards_plane : std::numeric_limits<double>::infinity();
    if (!(r > 0.0)) r = r0 + reach; // the plane lies behind the light along this ray
    r = std::clamp(r, r0 - reach, r0 + reach);
    const glm::dvec3 q = position + r * d;
    const double tolerance =
        kOffsetScale * std::max(hit.scale, point_scale(q)) + kReceiverPlaneTolerance * glm::length(q - hit.p);
    const double length = r - tolerance; // from q, beyond the receiver's own surface, to the light
    stats.add(length > 0.0 && ctx.tracer.occluded(q - tolerance * d, -d, length) ? 0.0 : 1.0);
  }
  return monte_carlo_result(stats);
}

} // namespace msm::reference::detail
