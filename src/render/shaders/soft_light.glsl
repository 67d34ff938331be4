// What soft.h's sizes need of light l (after shading.glsl): a directional light's spread (the
// renderer's msm_soft_spread) over an orthographic map; a spot light's, a sphere of radius soft.w,
// msm_spot_soft_spread where the lookup lies in its perspective map of radial depth, and its
// nearest blocker's depth.
#include "msm/soft.h"

struct SoftLight {
  vec2 spread;
  float near_depth; // [-1,1]
  bool perspective;
};

SoftLight soft_light(int l, ShadowLookup s) {
  if (is_spot(l)) {
    float radius = lights[l].soft.w, range = lights[l].spot_position.w;
    vec2 spread = msm_spot_soft_spread(radius, range, lights[l].spot_axis.w, frame.shadow_map.x, s.t + 0.5f);
    return SoftLight(spread, msm_spot_soft_near_depth(radius, range), true);
  }
  return SoftLight(vec2(lights[l].soft.x, lights[l].soft.y), -1.0f, false);
}

// The flow's constant bias in [-1,1] depth (frame.soft.z): a spot light's grows with the distance
// like its hard shadows' (spot_lookup: relative to the map's width where the receiver is).
float soft_constant_bias(int l, ShadowLookup s) {
  return is_spot(l) ? frame.soft.z * 2.0f * lights[l].spot_axis.w * s.z : frame.soft.z;
}
