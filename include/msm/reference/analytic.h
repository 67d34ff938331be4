// msm::reference analytic answers: soft shadows that have a closed form, to check the ray tracer
// and the renderer's soft techniques against.
#pragma once

#include <glm/glm.hpp>

namespace msm::reference {

// A thin disc occluder: a cylinder of the given radius and thickness, its axis the y axis, centred
// center_height above the ground plane y = 0. The defaults are the values of the built-in scene
// "disc" (scenes/disc.json: radius 0.25, centred 1 above the origin, 1e-4 thick, light straight
// down with an angular extent of 10 degrees); a test of that scene's geometry keeps them in step.
struct DiscOccluder {
  double radius = 0.25;
  double center_height = 1.0;
  double thickness = 1e-4;
};

// Area of the intersection of two discs of radii a, b >= 0 whose centres are d >= 0 apart.
double disc_intersection_area(double d, double a, double b);

// The fraction of a directional disc light that the ground point p (y = 0; p.y is ignored) sees
// past `disc`: the soft visibility of msm::reference::render with Effect::soft on the "disc"
// scene.
//
// Preconditions (not checked beyond the extent's range): the light is straight down
// (towards_light = +Y), the ground is the plane y = 0 and nothing but the disc occludes it;
// 0 <= light_extent_deg < 90 (else std::invalid_argument), the disc's lower face above the ground.
//
// Light model (that of reference.h and of shadow-map soft shadows): a planar emitter at infinity,
// its directions normalize(L + (a, 0, b)) with (a, b) uniform over a disc of radius
// t = tan(extent / 2). Seen from p through that plane (unit distance), the disc's lower face
// (height h = center_height - thickness / 2) is a disc of radius radius / h centred at -p / h, so
// the hidden fraction is the discs' intersection area over pi t^2. Exact for the planar model
// and an infinitely thin disc; the upper face of a thick one peeks out past the lower by at most
// thickness * t / h^2 in that plane (visibility off by < 1e-4 for the "disc" scene: 1e-4 * tan 5
// deg against a light of radius tan 5 deg), and a polygonal outline of n segments shrinks the
// radius by up to radius * (1 - cos(pi / n)) (3e-6 r at 1024). Extent 0 gives the hard shadow
// (1 outside the disc's shadow, 0 inside, 1 on its rim).
double disc_occluder_visibility(glm::dvec3 ground_point, double light_extent_deg, const DiscOccluder& disc = {});

} // namespace msm::reference
