// The push constants of every light-probe shader (probe_*.comp, through probe_common.glsl) and of
// msm::probe::DeviceProbe (device_probe.cpp), declared once for both (shared-header rules:
// include/msm/shared.h). std430 in GLSL; the C++ layout is asserted below.
#ifndef MSM_PROBE_PUSH_H
#define MSM_PROBE_PUSH_H
#include "msm/shared.h"

MSM_BEGIN

struct ProbePush {
  ivec2 panorama;    // width, height of the equirectangular panorama
  int size;          // m: texels per cube face side
  int supersampling; // ss² bilinear samples per cube texel
  vec2 cos_sin;      // of the probe's rotation about +Y
  float scale;       // the tables' fixed-point scale (msm::probe::table_scale)
  float inv_scale;
  int count;         // regions of the cut
  int horizon_split; // 1: the cut starts from ten regions (msm_first_region)
  ivec2 pad;
};

MSM_END

#if MSM_CPP
#include <cstddef>
static_assert(sizeof(msm::ProbePush) == 48 && offsetof(msm::ProbePush, supersampling) == 12 &&
                  offsetof(msm::ProbePush, cos_sin) == 16 && offsetof(msm::ProbePush, inv_scale) == 28 &&
                  offsetof(msm::ProbePush, horizon_split) == 36,
              "ProbePush: the std430 layout of the shaders' push constant block");
#endif

#endif // MSM_PROBE_PUSH_H
