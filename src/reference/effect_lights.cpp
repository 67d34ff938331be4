// hard over every light of a scene with spot or point lights: exact visibility of each light at
// the visible point (one shadow ray per light that lights it), and the direct light they bring.
#include "internal.h"
#include "msm/shading.h"

namespace msm::reference::detail {

namespace {

// One light's contribution: its irradiance on a facing surface E, unit direction towards it, and
// how far a shadow ray towards it runs (infinity for a directional light).
struct LightAtPoint {
  glm::dvec3 irradiance{0.0}, towards{0.0, 1.0, 0.0};
  double distance = std::numeric_limits<double>::infinity();
};

LightAtPoint at_point(const scene::DirectionalLight& light) {
  return {glm::dvec3(light.irradiance), glm::normalize(glm::dvec3(light.towards_light))};
}

LightAtPoint at_point(const scene::LocalLight& light, const glm::dvec3& p) {
  const glm::dvec3 to = glm::dvec3(light.position) - p;
  const double distance = glm::length(to);
  return {glm::dvec3(light.irradiance_at(glm::vec3(p))), distance > 0.0 ? to / distance : glm::dvec3(0.0, 1.0, 0.0),
          distance};
}

} // namespace

LightsSample hard_lights(const EffectContext& ctx, const SurfaceHit& hit, const glm::dvec3& n) {
  const scene::Scene& scene = ctx.tracer.scene();
  LightsSample out;
  double weight_sum = 0.0, weighted = 0.0;
  bool first = true;
  const auto add = [&](const LightAtPoint& l) {
    const double n_dot_l = glm::dot(n, l.towards);
    if (first) out.n_dot_l = n_dot_l;
    first = false;
    const double weight = double(msm_luminance(glm::vec3(l.irradiance))) * std::max(n_dot_l, 0.0);
    if (!(weight > 0.0)) return; // no light arrives: nothing to trace
    const glm::dvec3 origin = offset_origin(hit.p, hit.normal, hit.scale, l.towards);
    const double tfar = std::isfinite(l.distance) ? glm::length(hit.p + l.distance * l.towards - origin) : l.distance;
    const bool visible = !ctx.tracer.occluded(origin, l.towards, tfar);
    ++out.rays;
    out.direct +=
        glm::dvec3(msm_direct_light(glm::vec3(l.irradiance), float(n_dot_l), glm::vec3(visible ? 1.0f : 0.0f)));
    weight_sum += weight;
    weighted += visible ? weight : 0.0;
  };
  for (const scene::DirectionalLight& l : scene.lights) add(at_point(l));
  for (const scene::LocalLight& l : scene.local_lights) add(at_point(l, hit.p));
  out.visible = weight_sum > 0.0 ? weighted / weight_sum : 0.0;
  return out;
}

} // namespace msm::reference::detail
