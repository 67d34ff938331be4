// Closed-form soft visibility (see msm/reference/analytic.h).
#include "msm/reference/analytic.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace msm::reference {

double disc_intersection_area(double d, double a, double b) {
  constexpr double pi = std::numbers::pi;
  if (d >= a + b) return 0.0;
  if (d <= std::abs(a - b)) return pi * std::min(a, b) * std::min(a, b);
  // Two circular segments; the clamps absorb rounding at tangency.
  const double ca = std::clamp((d * d + a * a - b * b) / (2.0 * d * a), -1.0, 1.0);
  const double cb = std::clamp((d * d + b * b - a * a) / (2.0 * d * b), -1.0, 1.0);
  const double k = (-d + a + b) * (d + a - b) * (d - a + b) * (d + a + b);
  return a * a * std::acos(ca) + b * b * std::acos(cb) - 0.5 * std::sqrt(std::max(0.0, k));
}

double disc_occluder_visibility(glm::dvec3 p, double light_extent_deg, const DiscOccluder& disc) {
  if (!(light_extent_deg >= 0.0 && light_extent_deg < 90.0))
    throw std::invalid_argument("disc_occluder_visibility: light extent " + std::to_string(light_extent_deg) +
                                " outside [0, 90) degrees");
  const double h = disc.center_height - 0.5 * disc.thickness; // the lower face
  const double d = std::hypot(p.x, p.z) / h;                  // distance of the disc's image
  const double occluder = disc.radius / h;                    // and its radius, both in tan units
  const double light = std::tan(light_extent_deg * std::numbers::pi / 360.0);
  if (light == 0.0) return d < occluder ? 0.0 : 1.0;
  return 1.0 - disc_intersection_area(d, light, occluder) / (std::numbers::pi * light * light);
}

} // namespace msm::reference
