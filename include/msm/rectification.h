// The non-linear rectification of prefiltered single scattering (JCGT 2017 §5.1.1, Appendix A):
// a shadow map in which every view ray is one row at constant depth, so that prefix sums along
// the rows integrate the light's visibility along every view ray at once.
//
// Rectification space: light view space with the camera at the origin. Its z axis is the light's
// direction of TRAVEL (−towards_light), x and y any orthonormal pair across it. A point p there has
//   r = |(p.x, p.y)|          the distance of its light ray from the camera
//   φ = atan2(p.y, p.x)       the azimuth in [0, 2π): the epipolar slice
//   θ = atan2(r, p.z)         the inclination from +z in [0, π]
// and the rectified map stores, for texel (u, v):  u ~ r, v ~ φ, depth ~ π − θ.
// A light ray has constant (r, φ): one texel; along it θ falls from π (towards the light) to 0, so
// the depth π − θ grows with the distance from the light, as in a shadow map. A view ray has
// constant (φ, θ): one row, one depth, with r = t sin θ at distance t from the camera. Looking
// into the light is θ = π (depth 0), looking away θ = 0.
//
// Normalization into [0,1]³ (RectifiedBounds, Appendix A):
//   u = r / r_max,   v = ((φ − φ_min) mod 2π) / φ_span,   depth = (θ_max − θ) / (θ_max − θ_min).
// The bounds cover the whole view frustum (the far plane's corners and the camera; the near plane
// is ignored, since scattering accumulates from the camera on), with a guard band of 10% on θ
// against leaking (§5.1.1), clamped to [0, π]. If the light's direction or its opposite lies in the
// view (the epipole in view: looking into the light or away from it), φ spans the full circle:
// then rows 0 and height − 1 are neighbours, and the map is sampled with repeat addressing in v
// (clamp-to-edge otherwise, and always in u).
//
// Functions (shared GLSL/C++, shared.h rules):
//   msm_rectification_frame(camera, towards_light)           the frame (origin and axes)
//   msm_to_rectification_space(frame, world) / msm_from_rectification_space(frame, p)
//   msm_rectified_spherical(p)                               (r, φ, θ)
//   msm_rectification_bounds(frame, far_corners_world)       Appendix A: RectifiedBounds
//   msm_rectified_coordinates(bounds, p)                     (u, v, depth) of a point, unclamped
//   msm_rectified_depth(bounds, θ), msm_rectified_depth_of_rz(bounds, r, z)   depth in [0,1], clamped
//   msm_rectified_r_phi(bounds, uv), msm_rectified_light_ray_point(frame, bounds, uv)   the inverse
//   msm_slice_inclination_range(bounds, φ)                   θ range of the view in slice φ
//   msm_rectified_row_step(bounds, v, width)                 Δ(v) of §5.1.1
//   msm_prefix_sum_weight(σt, Δ, j)                          w(j, v) of §5.1.1
//   msm_prefix_sum_lod(du, dv, size, full_circle)            App. D.5's mip level of a pixel's lookup
//   msm_rectified_ray_step / msm_rectified_view_ray_step     a view ray's own step Δ
//   msm_transmittance_layer_range / _step / _lookup          K transmittance layers (Δ_k, the mix)
//   msm_prefix_sum_step(bounds, v, width, σt, k, K)          the step of layer k of row v
//   msm_prefix_sum_lookup_u(bounds, r, width)                where a view ray of reach r reads
//   msm_rectified_view_lookup(frame, bounds, end_world, width)  a pixel's (u, v, depth) lookup
// Resampling (§5.2), per rectified texel, from the scene's shadow map:
//   msm_rectified_one_depth(bounds, r, depth_to_z, map_depth)           without filtering
//   msm_rectified_two_depths(bounds, r, depth_to_z, map_moments)        filtered (Algorithm 2)
//   msm_rectified_resampling_lod(r_phi, step, map_per_x, map_per_y)     the filtered sample's mip level
//   msm_rectified_moments4 / msm_rectified_moments6 / msm_rectified_csm(two_depths[, terms])
// then the storage transform of the technique (msm_theta4_star, msm_theta6_star, msm_csm_to_unorm
// per texel; quantize.h, baselines.h), which commutes with the prefix sums (both are affine).
// Spot lights (the section at the end: columns are the angle ψ at the light, the depth the angle γ
// at the camera):
//   msm_spot_rectification_frame, msm_spot_psi, msm_spot_psi_max, msm_spot_light_ray_direction
//   msm_spot_cone_phi_range, msm_spot_rectified_bounds                  ψ_max and the slices of the cone
//   msm_spot_rectified_signed_depth / msm_spot_rectified_one_depth     resampling the spot's map
//   msm_spot_row_gamma, msm_spot_prefix_sum_weight                      the prefix sums' weights
//   msm_spot_view_lookup                                                a pixel's (u, v, depth)
#ifndef MSM_RECTIFICATION_H
#define MSM_RECTIFICATION_H
#include "msm/baselines.h"
#include "msm/moments.h"
#include "msm/scattering.h"
#include "msm/shared.h"
#include "msm/three_moments.h"

MSM_BEGIN

struct RectificationFrame {
  vec3 origin; // the camera position (world)
  vec3 x_axis; // unit, across the light
  vec3 y_axis; // unit, across the light
  vec3 z_axis; // unit, the light's direction of travel (−towards_light)
};

// Any orthonormal frame with z = −towards_light; x from the world axis least aligned with z.
// Precondition: towards_light non-zero (normalized here).
MSM_FN RectificationFrame msm_rectification_frame(vec3 camera, vec3 towards_light) {
  vec3 z = normalize(-towards_light);
  vec3 a = abs(z.x) < 0.57f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f);
  vec3 x = normalize(cross(a, z));
  return RectificationFrame(camera, x, cross(z, x), z);
}

MSM_FN vec3 msm_to_rectification_space(RectificationFrame f, vec3 world) {
  vec3 d = world - f.origin;
  return vec3(dot(f.x_axis, d), dot(f.y_axis, d), dot(f.z_axis, d));
}
MSM_FN vec3 msm_from_rectification_space(RectificationFrame f, vec3 p) {
  return f.origin + p.x * f.x_axis + p.y * f.y_axis + p.z * f.z_axis;
}

// atan2 that is defined at the origin (GLSL's atan(0, 0) is not): 0 there.
MSM_FN float msm_atan2_safe(float y, float x) { return (x == 0.0f && y == 0.0f) ? 0.0f : atan(y, x); }

// (r, φ, θ) of a point in rectification space, φ in [0, 2π), θ in [0, π]. The camera itself (the
// origin) gets (0, 0, 0).
MSM_FN vec3 msm_rectified_spherical(vec3 p) {
  float r = length(vec2(p.x, p.y));
  float phi = msm_atan2_safe(p.y, p.x);
  phi = phi < 0.0f ? phi + MSM_TWO_PI : phi;
  phi = phi < MSM_TWO_PI ? phi : 0.0f; // −0 rounding up to 2π
  return vec3(r, phi, msm_atan2_safe(r, p.z));
}

struct RectifiedBounds {
  float r_max;     // > 0
  float phi_min;   // [0, 2π)
  float phi_span;  // (0, 2π]; v = ((φ − φ_min) mod 2π) / φ_span
  float theta_min; // with the guard band, in [0, π]
  float theta_max; // > theta_min
  vec3 side0;      // inward normals of the frustum's four side planes (rectification space,
  vec3 side1;      // through the origin): the view's inclinations per slice (Δ(v))
  vec3 side2;
  vec3 side3;
  float view_theta_min; // the view's inclinations without the guard band
  float view_theta_max;
};

MSM_FN vec3 msm_rectified_side(RectifiedBounds b, int i) {
  return i == 0 ? b.side0 : (i == 1 ? b.side1 : (i == 2 ? b.side2 : b.side3));
}

// The inclination of a direction (unnormalized) in rectification space.
MSM_FN float msm_inclination(vec3 d) { return msm_atan2_safe(length(vec2(d.x, d.y)), d.z); }

// Relative padding of r_max and absolute padding of φ (radians): the bounds come from float corner
// coordinates; the padding keeps pixels computed with other roundings inside the map.
const float MSM_RECT_R_PAD = 1.0e-4f;
const float MSM_RECT_PHI_PAD = 1.0e-3f;
// The epipole counts as in view when the light's axis is within this angle (radians, as the sine
// of the angle to a side plane) of the frustum: near the epipole the corners' azimuths are
// ill-conditioned, and the full circle is always a cover.
const float MSM_RECT_EPIPOLE_TOLERANCE = 1.0e-3f;
// §5.1.1: the θ interval is stretched by 10% (5% on each side).
const float MSM_RECT_THETA_GUARD = 0.1f;

// Appendix A. far_corners_world: the four corners of the far plane (or of any plane cutting the
// frustum where the scene ends), in world space, IN ORDER AROUND THE QUAD (columns of the
// mat4x3). Returns the bounds of r, φ and θ over the pyramid from the camera to that quad:
//  - r_max: r is convex, so its maximum over the pyramid is at a corner (r = 0 at the camera);
//  - φ: the epipole (±z) is in view iff it satisfies the four side planes; then the full circle,
//    else the widest pair of corner azimuths (the pyramid's projection is a wedge below π);
//  - θ: at the corners, at the critical points of the normalized z along the four edges
//    (Appendix A's t), and 0 or π inside if +z or −z is in view; then the 10% guard band.
MSM_FN RectifiedBounds msm_rectification_bounds(RectificationFrame f, mat4x3 far_corners_world) {
  mat4x3 q;
  vec3 centre = vec3(0.0f);
  for (int j = 0; j < 4; ++j) {
    q[j] = msm_to_rectification_space(f, far_corners_world[j]);
    centre += 0.25f * q[j];
  }
  // Side planes through the origin and consecutive corners, normals turned inwards (unit).
  mat4x3 n;
  bool plus_z = true, minus_z = true;
  for (int j = 0; j < 4; ++j) {
    vec3 c = cross(q[j], q[(j + 1) % 4]);
    c = normalize(dot(c, centre) < 0.0f ? -c : c);
    n[j] = c;
    plus_z = plus_z && c.z >= -MSM_RECT_EPIPOLE_TOLERANCE;
    minus_z = minus_z && c.z <= MSM_RECT_EPIPOLE_TOLERANCE;
  }
  float r_max = 0.0f;
  float theta_lo = MSM_PI, theta_hi = 0.0f;
  for (int j = 0; j < 4; ++j) {
    vec3 a = q[j];
    r_max = max(r_max, length(vec2(a.x, a.y)));
    float theta = msm_inclination(a);
    theta_lo = min(theta_lo, theta);
    theta_hi = max(theta_hi, theta);
    // Critical point of (a + t d).z / |a + t d| on the edge to the next corner.
    vec3 d = q[(j + 1) % 4] - a;
    float ad = dot(a, d);
    float denominator = d.z * ad - a.z * dot(d, d);
    float t = (a.z * ad - d.z * dot(a, a)) / denominator;
    if (denominator != 0.0f && t > 0.0f && t < 1.0f) {
      float theta_edge = msm_inclination(a + t * d);
      theta_lo = min(theta_lo, theta_edge);
      theta_hi = max(theta_hi, theta_edge);
    }
  }
  if (plus_z) theta_lo = 0.0f;
  if (minus_z) theta_hi = MSM_PI;
  float phi_min = 0.0f, phi_span = MSM_TWO_PI;
  if (!(plus_z || minus_z)) {
    // The widest pair: the angle between corner azimuths, oriented counter-clockwise.
    float widest = -1.0f;
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        vec2 pj = vec2(q[j].x, q[j].y), pk = vec2(q[k].x, q[k].y);
        float ccw = pj.x * pk.y - pj.y * pk.x;
        float angle = msm_atan2_safe(ccw, dot(pj, pk)); // from j to k, in (−π, π]
        if (angle > widest) {
          widest = angle;
          phi_min = msm_rectified_spherical(q[j]).y;
        }
      }
    phi_span = min(widest + 2.0f * MSM_RECT_PHI_PAD, MSM_TWO_PI);
    phi_min = phi_span < MSM_TWO_PI ? phi_min - MSM_RECT_PHI_PAD : 0.0f;
    phi_min = phi_min < 0.0f ? phi_min + MSM_TWO_PI : phi_min;
  }
  float guard = 0.5f * MSM_RECT_THETA_GUARD * (theta_hi - theta_lo);
  return RectifiedBounds(r_max * (1.0f + MSM_RECT_R_PAD), phi_min, phi_span, max(theta_lo - guard, 0.0f),
                         min(theta_hi + guard, MSM_PI), n[0], n[1], n[2], n[3], theta_lo, theta_hi);
}

// Rectified depth in [0,1] (π − θ shifted and scaled), clamped: occluders beyond the bounds
// land on the ends, as §5.2 clamps them.
MSM_FN float msm_rectified_depth(RectifiedBounds b, float theta) {
  return msm_saturate((b.theta_max - theta) / (b.theta_max - b.theta_min));
}
// ... of the point at distance r from the camera's light ray and at z along the light.
MSM_FN float msm_rectified_depth_of_rz(RectifiedBounds b, float r, float z) {
  return msm_rectified_depth(b, msm_atan2_safe(r, z));
}

// (u, v, depth) of a point p in rectification space, NOT clamped: inside [0,1]³ for every point
// of the view frustum (tested). v wraps around the circle from φ_min.
MSM_FN vec3 msm_rectified_coordinates(RectifiedBounds b, vec3 p) {
  vec3 s = msm_rectified_spherical(p);
  float dphi = s.y - b.phi_min;
  dphi = dphi < 0.0f ? dphi + MSM_TWO_PI : dphi;
  return vec3(s.x / b.r_max, dphi / b.phi_span, (b.theta_max - s.z) / (b.theta_max - b.theta_min));
}

// The inverse for texels: (r, φ) of the light ray at texture coordinates uv in [0,1]² (texel
// centres are uv = ((i + 0.5) / width, (j + 0.5) / height)).
MSM_FN vec2 msm_rectified_r_phi(RectifiedBounds b, vec2 uv) {
  return vec2(uv.x * b.r_max, b.phi_min + uv.y * b.phi_span);
}
// A world point on that light ray: the one in the plane through the camera across the light
// (rectification z = 0). The ray is this point + s · frame.z_axis; its occluders' depths follow
// from their z = s with msm_rectified_depth_of_rz(bounds, r, s).
MSM_FN vec3 msm_rectified_light_ray_point(RectificationFrame f, RectifiedBounds b, vec2 uv) {
  vec2 rp = msm_rectified_r_phi(b, uv);
  return msm_from_rectification_space(f, vec3(rp.x * cos(rp.y), rp.x * sin(rp.y), 0.0f));
}

// The inclinations of the view's directions in the epipolar slice φ (the half-plane of the z axis
// at azimuth φ): the intersection over the four side planes n of {θ in [0, π] : n · d(θ) >= 0},
// d(θ) = (sin θ cos φ, sin θ sin φ, cos θ). Each is the half-circle around θ = α, the angle of
// (n_ρ, n.z) with n_ρ = n.x cos φ + n.y sin φ, cut to [0, π]: one interval. A slice outside the
// view (empty intersection) gets the view's whole range.
MSM_FN vec2 msm_slice_inclination_range(RectifiedBounds b, float phi) {
  float lo = 0.0f, hi = MSM_PI;
  float c = cos(phi), s = sin(phi);
  for (int i = 0; i < 4; ++i) {
    vec3 n = msm_rectified_side(b, i);
    float alpha = msm_atan2_safe(n.x * c + n.y * s, n.z); // in (−π, π]
    alpha = alpha < -0.5f * MSM_PI ? alpha + MSM_TWO_PI : alpha;
    lo = max(lo, alpha - 0.5f * MSM_PI);
    hi = min(hi, alpha + 0.5f * MSM_PI);
  }
  return lo <= hi ? vec2(lo, hi) : vec2(b.view_theta_min, b.view_theta_max);
}

// Floor of sin θ in Δ(v): slices whose mean inclination is within 1e-3 of the light's axis.
const float MSM_RECT_MIN_SIN = 1.0e-3f;

// Δ(v) of §5.1.1: the world distance along the view rays of row v (texture coordinate, e.g.
// (j + 0.5) / height) between successive texels of a row `width` texels wide, taken at the mean of
// the slice's smallest and largest inclination: (r_max / width) / sin θ_mean.
MSM_FN float msm_rectified_row_step(RectifiedBounds b, float v, float width) {
  vec2 range = msm_slice_inclination_range(b, b.phi_min + v * b.phi_span);
  float sin_mean = max(sin(0.5f * (range.x + range.y)), MSM_RECT_MIN_SIN);
  return b.r_max / (width * sin_mean);
}

// w(j, v) of §5.1.1 for texel j >= 0 of a row (0-based): the transmittance integral over the
// view-ray segment [j Δ, (j + 1) Δ] that the texel stands for. The prefix sums
// b_Σ(j) = Σ_{i <= j} w_i b_i / Σ_{i <= j} w_i then average the texels over [0, (j + 1) Δ].
MSM_FN float msm_prefix_sum_weight(float extinction, float delta, float j) {
  return msm_transmittance_integral(extinction, j * delta, (j + 1.0f) * delta);
}

// ---- Transmittance layers (beyond the paper: a step per ray instead of one per row) ----
// Δ(v) above is one step per row, the paper's heuristic; a view ray of inclination θ has its own
// step Δ = (r_max / width) / sin θ, and the normalized prefix sums depend on Δ only through the
// ratio e^(−σt Δ) of successive weights. K "transmittance layers" are K prefix sums of the same
// rectified map with K steps Δ_k spread geometrically over the view's range of steps; a pixel mixes
// the two layers that bracket its own Δ (linearly in log Δ), which keeps one (bilinear) lookup per
// layer, two per pixel. The mix is of the stored vectors (moments after the affine Θ* or the CSM
// coefficients): a convex combination of two prefix sums is the prefix sum with the convex
// combination of their weights, a valid distribution whose weights lie between the two layers'.
// K = 1 is the paper's single Δ(v) per row (msm_rectified_row_step).
const int MSM_RECT_MAX_LAYERS = 16;
// The layers' range is clamped to where the weights differ: above σt Δ = MAX_TAU the first texel
// holds at least 1 − 1/e of a row's weight (larger steps read nearly the same), below a row's optical
// thickness σt Δ width = MIN_TAU the weights are uniform within 1% (every smaller step reads the same).
const float MSM_RECT_LAYER_MAX_TAU = 1.0f;
const float MSM_RECT_LAYER_MIN_TAU = 0.01f;

// The step along a view ray between successive texels of a row `width` texels wide, for a ray
// whose inclination has the sine sin_theta (floored at MSM_RECT_MIN_SIN like Δ(v)).
MSM_FN float msm_rectified_ray_step(RectifiedBounds b, float sin_theta, float width) {
  return b.r_max / (width * max(sin_theta, MSM_RECT_MIN_SIN));
}
// ... of the view ray along the unit world direction `direction` (sin θ from its rectification
// space components across the light).
MSM_FN float msm_rectified_view_ray_step(RectificationFrame f, RectifiedBounds b, vec3 direction, float width) {
  float sin_theta = length(vec2(dot(f.x_axis, direction), dot(f.y_axis, direction)));
  return msm_rectified_ray_step(b, sin_theta, width);
}

// The range (Δ_lo, Δ_hi) of the layers: the steps of the view's inclinations [view_theta_min,
// view_theta_max] (sin θ largest at π/2 if inside, smallest at an end), clamped by the optical
// thickness bounds above (extinction <= 0: no clamp). Δ_lo <= Δ_hi.
MSM_FN vec2 msm_transmittance_layer_range(RectifiedBounds b, float extinction, float width) {
  float s0 = sin(b.view_theta_min), s1 = sin(b.view_theta_max);
  bool right_angle = b.view_theta_min <= 0.5f * MSM_PI && b.view_theta_max >= 0.5f * MSM_PI;
  float hi = msm_rectified_ray_step(b, min(s0, s1), width);
  float lo = msm_rectified_ray_step(b, right_angle ? 1.0f : max(s0, s1), width);
  float sigma = max(extinction, 1.0e-30f);
  hi = min(hi, MSM_RECT_LAYER_MAX_TAU / sigma);
  lo = min(max(lo, MSM_RECT_LAYER_MIN_TAU / (sigma * width)), hi);
  return vec2(lo, hi);
}

// Δ_k of layer k in [0, K): Δ_lo (Δ_hi / Δ_lo)^(k / (K − 1)); K = 1: Δ_lo.
MSM_FN float msm_transmittance_layer_step(vec2 range, float layer, float layers) {
  return layers > 1.0f ? range.x * pow(range.y / range.x, layer / (layers - 1.0f)) : range.x;
}

// The layers a ray of step delta reads: (k0, t), the mix (1 − t) layer k0 + t layer k0 + 1, with t
// linear in log Δ between the bracketing steps Δ_k0 <= delta <= Δ_k0+1 (geometrically spaced, so
// x = (K − 1) log(delta / Δ_lo) / log(Δ_hi / Δ_lo) and k0 = floor(x)); steps outside the range
// read its end layer. K = 1 or an empty range: (0, 0). (Measured against a mix that keeps the ray's
// mean distance: that one is worse with few layers.)
MSM_FN vec2 msm_transmittance_layer_lookup(vec2 range, float delta, float layers) {
  float span = log(range.y / range.x);
  float x = span > 0.0f && layers > 1.0f ? msm_saturate(log(delta / range.x) / span) * (layers - 1.0f) : 0.0f;
  float k0 = min(floor(x), max(layers - 2.0f, 0.0f));
  return vec2(k0, x - k0);
}

// The step of layer k of row v in a map of `layers` layers: the paper's Δ(v) for one layer, else Δ_k.
MSM_FN float msm_prefix_sum_step(RectifiedBounds b, float v, float width, float extinction, float layer, float layers) {
  return layers > 1.0f
             ? msm_transmittance_layer_step(msm_transmittance_layer_range(b, extinction, width), layer, layers)
             : msm_rectified_row_step(b, v, width);
}

// JCGT App. D.5: the mip level at which a pixel reads the prefix sums of a width x height map, from
// the screen derivatives du = (du/dx, du/dy) and dv of its lookup: the smaller of the footprints
// along the rows and across them, each the larger derivative in texels, log2, >= 0. dv wraps where
// φ spans the full circle (the seam between v = 1 and v = 0 is no jump). The smaller one, because
// a mip averages both ways: near the epipole the rows converge (a large footprint across them) while
// u barely moves, and at silhouettes u jumps with the ray's length while v does not; the larger
// footprint would average prefix sums of other ray lengths or other slices into the pixel.
MSM_FN float msm_prefix_sum_lod(vec2 du, vec2 dv, vec2 size, bool full_circle) {
  vec2 d = full_circle ? dv - floor(dv + 0.5f) : dv;
  float along = max(abs(du.x), abs(du.y)) * size.x, across = max(abs(d.x), abs(d.y)) * size.y;
  return log2(max(min(along, across), 1.0f));
}

// The texture coordinate u at which to sample the prefix sums for a view ray ending at distance
// r from the camera's light ray (r = s sin θ for a ray of length s): prefix texel j covers
// [0, (j + 1) Δ], i.e. reach (j + 1) r_max / width, and its centre is at u = (j + 0.5) / width,
// so u = r / r_max − 0.5 / width (linear filtering interpolates between whole texels; rays
// shorter than one texel read texel 0 with clamp-to-edge addressing).
MSM_FN float msm_prefix_sum_lookup_u(RectifiedBounds b, float r, float width) { return r / b.r_max - 0.5f / width; }

// The lookup of a pixel whose view ray ends at end_world: (u, v, depth) with u where the prefix
// sums of a map `width` texels wide are read (msm_prefix_sum_lookup_u), v the row and depth the
// ray's rectified depth in [0,1] (the receiver depth zf = msm_signed_depth(depth) for moments).
MSM_FN vec3 msm_rectified_view_lookup(RectificationFrame f, RectifiedBounds b, vec3 end_world, float width) {
  vec3 c = msm_rectified_coordinates(b, msm_to_rectification_space(f, end_world));
  return vec3(c.x - 0.5f / width, c.y, c.z);
}

// ---- Resampling (§5.2) ----
// The source shadow map is orthographic along the light: its depth d (in its own convention,
// [0,1] or [-1,1]) lies at rectification z = depth_to_z.x * d + depth_to_z.y on the light ray
// (depth_to_z.x > 0: depth grows along the light's travel). r is the texel's distance from the
// camera's light ray (msm_rectified_r_phi(bounds, uv).x). Depths come back in rectified SIGNED
// depth [-1, 1], clamped (occluders beyond the bounds land on its ends).
MSM_FN float msm_rectified_signed_depth_of_map_depth(RectifiedBounds b, float r, vec2 depth_to_z, float map_depth) {
  return msm_signed_depth(msm_rectified_depth_of_rz(b, r, depth_to_z.x * map_depth + depth_to_z.y));
}

// Without filtering: the map's depth at the texel, weight 1.
MSM_FN TwoDepths msm_rectified_one_depth(RectifiedBounds b, float r, vec2 depth_to_z, float map_depth) {
  float z = msm_rectified_signed_depth_of_map_depth(b, r, depth_to_z, map_depth);
  return TwoDepths(vec2(z, z), vec2(1.0f, 0.0f));
}

// With filtering: a filtered sample of the map's four moments (canonical b1..b4, after the map's
// inverse quantization transform, in the map's depth convention) turned into two depths by JCGT
// Algorithm 2 (three_moments.h; a single depth for zero variance), each mapped to rectified depth.
// The weights stay, and so does the order z.x <= z.y: along one light ray the rectified depth
// grows monotonically with the map's depth (clamping may make both equal).
MSM_FN TwoDepths msm_rectified_two_depths(RectifiedBounds b, float r, vec2 depth_to_z, vec4 map_moments) {
  TwoDepths d = msm_two_depths_from_three_moments(vec3(map_moments[0], map_moments[1], map_moments[2]));
  return TwoDepths(vec2(msm_rectified_signed_depth_of_map_depth(b, r, depth_to_z, d.z.x),
                        msm_rectified_signed_depth_of_map_depth(b, r, depth_to_z, d.z.y)),
                   d.w);
}

// The level of detail of the filtered sample (§5.2: the scene's blurred, mipmapped moment map read
// with the footprint of one rectified texel). A rectified texel at (r, φ) = r_phi stands for the
// light rays of its cell: the rectification's Jacobian maps one texel step in u and in v to the
// displacements (in rectification space, across the light)
//   ∂p/∂u = step.x (cos φ, sin φ),   ∂p/∂v = r step.y (−sin φ, cos φ),
// step = (r_max / width, φ_span / height). The shadow map is orthographic along the light (the z
// axis), so its texel coordinates are affine in (p.x, p.y): map_per_x and map_per_y are the
// shadow-map texels per unit of rectification x and y (the light's projection of the frame's x
// and y axes, times half the map's size). The footprint's axes in shadow-map texels are then
// J_u = step.x (cos φ map_per_x + sin φ map_per_y) and J_v = r step.y (−sin φ map_per_x + cos φ map_per_y),
// and the level is the usual isotropic one of the longer axis, log2 max(|J_u|, |J_v|), never below
// 0 (a footprint within one texel reads the blurred mip 0).
MSM_FN float msm_rectified_resampling_lod(vec2 r_phi, vec2 step, vec2 map_per_x, vec2 map_per_y) {
  float c = cos(r_phi.y), s = sin(r_phi.y);
  vec2 ju = step.x * (c * map_per_x + s * map_per_y);
  vec2 jv = (r_phi.x * step.y) * (c * map_per_y - s * map_per_x);
  return log2(max(max(length(ju), length(jv)), 1.0f));
}

// The moments of w.x δ(z.x) + w.y δ(z.y): what a rectified texel stores before its transform.
MSM_FN vec4 msm_rectified_moments4(TwoDepths d) { return d.w.x * msm_moments4(d.z.x) + d.w.y * msm_moments4(d.z.y); }
MSM_FN Moments6 msm_rectified_moments6(TwoDepths d) {
  return msm_moments6_scale_add(msm_moments6_scale_add(Moments6(vec3(0.0f), vec3(0.0f)), msm_moments6(d.z.x), d.w.x),
                                msm_moments6(d.z.y), d.w.y);
}
// Klehm et al.'s convolution shadow map of the same distribution, on [0,1] depth (baselines.h).
MSM_FN CsmMoments msm_rectified_csm(TwoDepths d, int terms) {
  CsmMoments m = msm_csm_moments_scale_add(CsmMoments(mat4(0.0f), mat4(0.0f)),
                                           msm_csm_moments(msm_unit_depth(d.z.x), terms), d.w.x);
  return msm_csm_moments_scale_add(m, msm_csm_moments(msm_unit_depth(d.z.y), terms), d.w.y);
}

// ---- Spot lights: the rectification of a point source (docs/techniques.md, "Prefiltered single
// scattering from spot lights") ----
// Light at L, camera at p, d = |L − p|. The epipolar slices are the half-planes through the line
// L–p, at azimuth φ about it: the same φ as above in the camera's frame whose "towards the light"
// points at L (msm_spot_rectification_frame: z = (p − L) / d, L at z = −d). In a slice a LIGHT ray
// has its angle ψ at L from the direction L→p, a VIEW ray its angle γ at p from p→L, which is
// π − θ with θ the inclination above: a view ray is still a row at one rectified depth
// (θ_max − θ) / (θ_max − θ_min), and the bounds of θ, φ are msm_rectification_bounds' of the camera
// in that frame. Along a light ray γ grows monotonically from 0 (at L) towards π − ψ, so γ is its
// depth: texel (u, v) = (ψ / ψ_max, φ) stores the moments of the first occluder's γ. The view ray
// (φ, γ) from p to a point q crosses the light rays ψ in [0, ψ(q)]: a prefix of the row. Law of
// sines in the triangle (L, p, point): t = d sin ψ / sin(ψ + γ) from p, r = d sin γ / sin(ψ + γ)
// from L, dt/dψ = d sin γ / sin²(ψ + γ), hence dt / r² = dψ / h with h = d sin γ the light's
// distance from the view ray (scattering.h: msm_spot_ray_distances, msm_spot_dt_dpsi), and the in-scattering ∫ f I(ω) r⁻² exp(−σt t) V dt becomes
//   (1/h) ∫₀^ψ(q) f(ψ + γ) I(ω(φ, ψ)) exp(−σt t(ψ, γ)) V dψ
// (the scattering angle is ψ + γ): the inverse square is exact in ψ and the cone's factor I(ω)
// belongs to the texel. The phase and the transmittance depend on γ: the prefix sums weigh row v
// at one γ, the mean of the slice's view inclinations (msm_spot_row_gamma), as JCGT weighs a row
// with the Δ(v) of its mean θ. The stored RectifiedBounds hold ψ_max in r_max.

// The spot's frame: the camera's, its z axis from the light through the camera.
// Precondition: the camera is not at the light.
MSM_FN RectificationFrame msm_spot_rectification_frame(vec3 camera, vec3 light_position) {
  return msm_rectification_frame(camera, light_position - camera);
}

// ψ of a point p in that frame (the light at z = −d): its angle at the light from the direction
// light → camera, in [0, π].
MSM_FN float msm_spot_psi(vec3 p, float d) { return msm_atan2_safe(length(vec2(p.x, p.y)), p.z + d); }

// ψ_max: the light rays of the spot's outer cone (half-angle `outer`, unit axis `axis` in the
// frame's coordinates) make angles up to β + outer with +z, β the axis's angle from +z; rays
// beyond carry no light. The rectified map spans ψ in [0, ψ_max].
MSM_FN float msm_spot_psi_max(vec3 axis, float outer) {
  return min(msm_inclination(axis) + outer, MSM_PI) * (1.0f + MSM_RECT_R_PAD);
}

// The slices that the outer cone (half-angle `outer`, unit axis `axis` in the frame) reaches:
// (φ_min, φ_span) of its wedge about the z axis, the axis's azimuth ± asin(sin outer / sin β), with
// MSM_RECT_PHI_PAD on each side; the full circle (0, 2π) where the cone holds +z or −z (β <= outer
// or β >= π − outer). A pixel of another slice has no in-scattering from the spot.
MSM_FN vec2 msm_spot_cone_phi_range(vec3 axis, float outer) {
  float beta = msm_inclination(axis);
  if (beta <= outer || beta >= MSM_PI - outer) return vec2(0.0f, MSM_TWO_PI);
  float half_width = asin(min(sin(outer) / sin(beta), 1.0f)) + MSM_RECT_PHI_PAD;
  float phi = msm_rectified_spherical(axis).y - half_width;
  return vec2(phi < 0.0f ? phi + MSM_TWO_PI : phi, 2.0f * half_width);
}

// A spot light's bounds from the view's (msm_rectification_bounds of the spot's frame): ψ_max of the
// cone, and of the two wedges of slices, the view's and the cone's, the narrower (the lit slices
// in view lie in both; a lookup outside the cone's scatters nothing).
MSM_FN RectifiedBounds msm_spot_rectified_bounds(RectifiedBounds view, vec3 axis, float outer) {
  RectifiedBounds b = view;
  b.r_max = msm_spot_psi_max(axis, outer);
  vec2 cone = msm_spot_cone_phi_range(axis, outer);
  if (cone.y < b.phi_span) {
    b.phi_min = cone.x;
    b.phi_span = cone.y;
  }
  return b;
}

// The world direction of the light ray of texel coordinates uv (ψ = u ψ_max, φ of v).
MSM_FN vec3 msm_spot_light_ray_direction(RectificationFrame f, RectifiedBounds b, vec2 uv) {
  vec2 psi_phi = msm_rectified_r_phi(b, uv);
  float s = sin(psi_phi.x);
  return s * cos(psi_phi.y) * f.x_axis + s * sin(psi_phi.y) * f.y_axis + cos(psi_phi.x) * f.z_axis;
}

// Rectified signed depth [-1, 1] (clamped) of the point at `distance` from the light along the
// light ray ψ: the inclination of (distance sin ψ, distance cos ψ − d) as seen from the camera.
MSM_FN float msm_spot_rectified_signed_depth(RectifiedBounds b, float psi, float d, float distance) {
  return msm_signed_depth(msm_rectified_depth_of_rz(b, distance * sin(psi), distance * cos(psi) - d));
}
// Without filtering: the first occluder at `distance` along the light ray, weight 1.
MSM_FN TwoDepths msm_spot_rectified_one_depth(RectifiedBounds b, float psi, float d, float distance) {
  float z = msm_spot_rectified_signed_depth(b, psi, d, distance);
  return TwoDepths(vec2(z, z), vec2(1.0f, 0.0f));
}

// The γ at which row v (texture coordinate) is weighed: π − the mean of the slice's inclinations.
MSM_FN float msm_spot_row_gamma(RectifiedBounds b, float v) {
  vec2 range = msm_slice_inclination_range(b, b.phi_min + v * b.phi_span);
  return MSM_PI - 0.5f * (range.x + range.y);
}

// The weight of the light ray ψ in the prefix sums of a row weighed at γ: f(ψ + γ) I(ω) exp(−σt t)
// up to the factors common to the row (ρ σt, the intensity, dψ, 1/h), with f the Henyey–Greenstein
// phase of the scattering angle ψ + γ and `cone` the spot's cone factor of the ray (msm_spot_cone);
// 0 where the view ray never meets the light ray.
MSM_FN float msm_spot_prefix_sum_weight(float d, float psi, float gamma, float extinction, float g, float cone) {
  vec2 tr = msm_spot_ray_distances(d, psi, gamma);
  float half_angle = 0.5f * (psi + gamma);
  float s = sin(half_angle), c = cos(half_angle);
  float phase = msm_phase_henyey_greenstein_versines(2.0f * s * s, 2.0f * c * c, g);
  return tr.x >= 0.0f ? phase * cone * exp(-extinction * tr.x) : 0.0f;
}

// The lookup of a pixel whose view ray ends at end_world: (u, v, depth), u = ψ(end) / ψ_max −
// 0.5 / width (the prefix texel j's centre holds the rays up to (j + 1) ψ_max / width, as
// msm_prefix_sum_lookup_u), v the row and depth the ray's rectified depth (γ) in [0,1].
MSM_FN vec3 msm_spot_view_lookup(RectificationFrame f, RectifiedBounds b, float d, vec3 end_world, float width) {
  vec3 p = msm_to_rectification_space(f, end_world);
  vec3 c = msm_rectified_coordinates(b, p);
  return vec3(msm_spot_psi(p, d) / b.r_max - 0.5f / width, c.y, c.z);
}

MSM_END

#endif // MSM_RECTIFICATION_H
