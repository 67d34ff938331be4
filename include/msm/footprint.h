// The footprint of a screen pixel on a surface, from the camera's projection and the surface's
// plane (ray differentials, as pbrt's): where screen-space derivatives are wrong, filtered lookups
// pick the wrong mip. Finite differences over 2x2 quads extrapolate each triangle's plane
// equations into helper pixels; lavapipe clips triangles that cross the view frustum into fans of
// slivers, and their extrapolation spikes along every sliver edge, so dFdx/dFdy read coarse mips
// there (dashed dark lines across large ground planes). The footprint below depends on the point,
// the normal and the camera only, not on how the surface was cut into triangles.
#ifndef MSM_FOOTPRINT_H
#define MSM_FOOTPRINT_H
#include "msm/shared.h"

MSM_BEGIN

// World-space offsets of the surface point seen one pixel to the right (dp_dx) and one pixel down
// (dp_dy) of p.
struct MsmFootprint {
  vec3 dp_dx;
  vec3 dp_dy;
};

// The pixel footprint at p on the plane through p with unit normal n, seen through view_projection
// (world -> clip, any perspective or orthographic camera) on an image of `viewport` pixels. Screen
// position s(p) = (c.xy / c.w + 1) viewport / 2 with c = view_projection (p, 1); its Jacobian
// restricted to the plane's tangents (t, b) is inverted. At grazing view the footprint grows
// without bound: the determinant is kept away from zero so that the result stays finite (callers
// clamp the mip it selects).
MSM_FN MsmFootprint msm_surface_footprint(mat4 view_projection, vec2 viewport, vec3 p, vec3 n) {
  vec4 c = view_projection * vec4(p, 1.0f);
  vec3 row_x = vec3(view_projection[0][0], view_projection[1][0], view_projection[2][0]);
  vec3 row_y = vec3(view_projection[0][1], view_projection[1][1], view_projection[2][1]);
  vec3 row_w = vec3(view_projection[0][3], view_projection[1][3], view_projection[2][3]);
  float inv_w2 = 1.0f / (c.w * c.w);
  vec3 grad_x = (row_x * c.w - row_w * c.x) * (inv_w2 * 0.5f * viewport.x); // pixels per world unit
  vec3 grad_y = (row_y * c.w - row_w * c.y) * (inv_w2 * 0.5f * viewport.y);
  // A tangent frame of the plane (any: the result does not depend on it).
  vec3 t = msm_perpendicular(n);
  vec3 b = cross(n, t);
  float a00 = dot(grad_x, t), a01 = dot(grad_x, b), a10 = dot(grad_y, t), a11 = dot(grad_y, b);
  float det = a00 * a11 - a01 * a10;
  const float min_det = 1e-12f;
  if (!(abs(det) >= min_det)) det = det < 0.0f ? -min_det : min_det; // grazing (and NaN) -> huge
  float inv_det = 1.0f / det;
  // Columns of the inverse Jacobian: tangent-plane offsets of one pixel along screen x and y.
  return MsmFootprint(t * (a11 * inv_det) - b * (a10 * inv_det), b * (a00 * inv_det) - t * (a01 * inv_det));
}

MSM_END

#endif // MSM_FOOTPRINT_H
