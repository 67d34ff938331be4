// The median cut's first regions (msm::probe::median_cut on the CPU, probe_cut.comp on the
// device), written once for both: the six faces, or the ten regions of the horizon split.
#ifndef MSM_MEDIAN_CUT_H
#define MSM_MEDIAN_CUT_H
#include "msm/shared.h"

MSM_BEGIN

// Without the horizon split: the six faces, region k = face k. With it (median_cut's
// horizon_split), ten: each side face (+X, −X, +Z, −Z, whose v axis is −Y) as its upper half, rows [0, m/2) (v < 0,
// above the horizon y = 0), then its lower half, rows [m/2, m); ±Y whole, in face order:
// +X up, +X down, −X up, −X down, +Y, −Y, +Z up, +Z down, −Z up, −Z down. The cube map is always in
// world axes (a probe rotation turns about +Y while resampling, msm_probe_lookup_direction), so the
// middle row of a side face is the world's horizon whatever the rotation. m must be even.
struct MsmFirstRegion {
  int face;
  ivec4 rect; // x0, y0, x1, y1: texels [x0, x1) x [y0, y1)
};
MSM_FN int msm_first_region_count(bool horizon_split) { return horizon_split ? 10 : 6; }
MSM_FN MsmFirstRegion msm_first_region(int k, int m, bool horizon_split) {
  if (!horizon_split) return MsmFirstRegion(k, ivec4(0, 0, m, m));
  if (k == 4 || k == 5) return MsmFirstRegion(k - 2, ivec4(0, 0, m, m));
  int face = k < 4 ? k / 2 : k / 2 + 1;
  int lower = k % 2;
  return MsmFirstRegion(face, ivec4(0, lower * (m / 2), m, lower == 0 ? m / 2 : m));
}

MSM_END

#endif // MSM_MEDIAN_CUT_H
