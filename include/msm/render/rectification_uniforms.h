// The rectification of prefiltered single scattering (rectification.h) as the renderer's passes
// receive it: one per light of the frame, in a storage buffer (an std430 array; vec4 members only,
// so that std430 and C++ agree), and the functions that turn it back into the shared structs on
// both sides.
#ifndef MSM_RENDER_RECTIFICATION_UNIFORMS_H
#define MSM_RENDER_RECTIFICATION_UNIFORMS_H
#include "msm/rectification.h"
MSM_BEGIN

struct RectificationUniforms {
  vec4 origin, x_axis, y_axis, z_axis; // RectificationFrame (xyz)
  vec4 bounds0;                        // r_max, phi_min, phi_span, theta_min
  vec4 bounds1;                        // theta_max, view_theta_min, view_theta_max, unused
  vec4 side0, side1, side2, side3;     // the frustum's side normals (xyz)
  vec4 map;                            // x: width, y: height of the rectified map, z: the light
                                       // frustum's depth extent (world units from depth 0 to 1),
                                       // w: extinction σt (0 without a medium)
  vec4 spot;      // a spot light's rectification (rectification.h's spot section; bounds0.x holds ψ_max):
                  // x: d, the camera's distance from the light (0: a directional light), y: the phase
                  // function's g, z, w: cos of the outer and the inner cone's half-angle
  vec4 spot_axis; // xyz: the spot's unit axis (world)
};

MSM_FN RectificationUniforms msm_rectification_uniforms(RectificationFrame f, RectifiedBounds b, vec4 map) {
  return RectificationUniforms(
      vec4(f.origin, 0.0f), vec4(f.x_axis, 0.0f), vec4(f.y_axis, 0.0f), vec4(f.z_axis, 0.0f),
      vec4(b.r_max, b.phi_min, b.phi_span, b.theta_min), vec4(b.theta_max, b.view_theta_min, b.view_theta_max, 0.0f),
      vec4(b.side0, 0.0f), vec4(b.side1, 0.0f), vec4(b.side2, 0.0f), vec4(b.side3, 0.0f), map, vec4(0.0f), vec4(0.0f));
}

// Whether the rectification is a spot light's.
MSM_FN bool msm_rectification_is_spot(RectificationUniforms u) { return u.spot.x > 0.0f; }

MSM_FN RectificationFrame msm_rectification_frame_of(RectificationUniforms u) {
  return RectificationFrame(vec3(u.origin), vec3(u.x_axis), vec3(u.y_axis), vec3(u.z_axis));
}

MSM_FN RectifiedBounds msm_rectified_bounds_of(RectificationUniforms u) {
  return RectifiedBounds(u.bounds0.x, u.bounds0.y, u.bounds0.z, u.bounds0.w, u.bounds1.x, vec3(u.side0), vec3(u.side1),
                         vec3(u.side2), vec3(u.side3), u.bounds1.y, u.bounds1.z);
}

MSM_END

#if MSM_CPP
#include <cstddef>
// The std430 array stride of the passes' rects[].
static_assert(sizeof(msm::RectificationUniforms) == 13 * 16 && offsetof(msm::RectificationUniforms, map) == 10 * 16);
#endif

#endif // MSM_RENDER_RECTIFICATION_UNIFORMS_H
