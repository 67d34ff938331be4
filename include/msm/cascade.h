// Cascaded shadow maps: how much of a directional light's shading one cascade (one layer of the
// shadow-map arrays) takes at a view depth, the one formula the shading (shading.glsl) and the
// tests share. Adjacent cascades' weights sum to 1: over the band at a cascade's far end it fades
// out as the next fades in, so their shadows blend instead of meeting at a seam.
#ifndef MSM_CASCADE_H
#define MSM_CASCADE_H
#include "msm/shared.h"

MSM_BEGIN

// 0 below `from`, 1 above `to`, the cubic smoothstep between; a step at `to` where the band is empty.
MSM_FN float msm_cascade_ramp(float from, float to, float x) {
  if (!(to > from)) return x >= to ? 1.0f : 0.0f;
  float t = clamp((x - from) / (to - from), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// The weight of a cascade at view depth `depth` (the camera's, > 0): `cascade` holds the view depths
// where it rises from 0 (x) to 1 (y) and where it falls from 1 (z) to 0 (w), frame.h's
// LightUniforms::cascade. w <= 0: a light without cascades, weight 1.
MSM_FN float msm_cascade_weight(vec4 cascade, float depth) {
  if (cascade.w <= 0.0f) return 1.0f;
  return msm_cascade_ramp(cascade.x, cascade.y, depth) * (1.0f - msm_cascade_ramp(cascade.z, cascade.w, depth));
}

MSM_END

#endif
