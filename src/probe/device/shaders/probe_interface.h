// What the light-probe shaders (probe_*.comp, through probe_common.glsl) and
// msm::probe::DeviceProbe (device_probe.cpp) exchange, declared once for both (shared-header rules:
// include/msm/shared.h): the push constants, the descriptor bindings and the median cut's output
// buffer. std430 in GLSL (64-bit integers: the includer enables GL_EXT_shader_explicit_arithmetic_types_int64);
// the C++ layout is asserted below.
#ifndef MSM_PROBE_INTERFACE_H
#define MSM_PROBE_INTERFACE_H
#include "msm/shared.h"

// Descriptor bindings (storage buffers), per shader.
#define MSM_BINDING_PROBE_CUBE_PANORAMA 0  // probe_cube.comp: the equirectangular texels (vec4)
#define MSM_BINDING_PROBE_CUBE_FACES 1     //   the six faces it writes (vec4)
#define MSM_BINDING_PROBE_ROWS_CUBE 0      // probe_table_rows.comp: the six faces
#define MSM_BINDING_PROBE_ROWS_WEIGHTS 1   //   m² texel weights, then m texel-centre coordinates
#define MSM_BINDING_PROBE_ROWS_TABLES 2    //   the tables' row sums it writes
#define MSM_BINDING_PROBE_COLUMNS_TABLES 0 // probe_table_columns.comp: the tables, summed in place
#define MSM_BINDING_PROBE_CUT_TABLES 0     // probe_cut.comp: the tables
#define MSM_BINDING_PROBE_CUT_RESULT 1     //   ProbeCutResult

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

// The most regions of the device's median cut (msm::probe::kMaxDeviceLights).
const int MSM_PROBE_MAX_REGIONS = 256;

// One region of the cut (msm::probe::Region).
struct ProbeCutRegion {
  ivec4 rect; // x0, y0, x1, y1: texels [x0, x1) x [y0, y1)
  int face;
  uint lit; // 1: the region has energy and lights[t] is its light
  uint64_t fixed_energy;
  uint faces; // a group of whole faces: bit f per face f (face: the lowest); 0: the rectangle of face
  uint pad0, pad1, pad2;
};

// The area light of a region (msm_area_light_from_region's MsmAreaLight).
struct ProbeCutLight {
  vec4 direction_cone; // direction, cone_half_angle
  vec4 x_axis_half_x;
  vec4 y_axis_half_y;
  vec4 irradiance;
};

// probe_cut.comp's output: region t and, where lit, its light at index t.
struct ProbeCutResult {
  uint region_count;
  uint pad0, pad1, pad2;
  ProbeCutRegion regions[MSM_PROBE_MAX_REGIONS];
  ProbeCutLight lights[MSM_PROBE_MAX_REGIONS];
};

MSM_END

#if MSM_CPP
#include <cstddef>
static_assert(sizeof(msm::ProbeCutRegion) == 48 && offsetof(msm::ProbeCutRegion, fixed_energy) == 24 &&
                  offsetof(msm::ProbeCutRegion, faces) == 32 && sizeof(msm::ProbeCutLight) == 64 &&
                  offsetof(msm::ProbeCutResult, regions) == 16 &&
                  offsetof(msm::ProbeCutResult, lights) == 16 + 48 * msm::MSM_PROBE_MAX_REGIONS &&
                  sizeof(msm::ProbeCutResult) == 16 + (48 + 64) * msm::MSM_PROBE_MAX_REGIONS,
              "ProbeCutResult: the std430 layout of probe_cut.comp's output buffer");
static_assert(sizeof(msm::ProbePush) == 48 && offsetof(msm::ProbePush, supersampling) == 12 &&
                  offsetof(msm::ProbePush, cos_sin) == 16 && offsetof(msm::ProbePush, inv_scale) == 28 &&
                  offsetof(msm::ProbePush, horizon_split) == 36,
              "ProbePush: the std430 layout of the shaders' push constant block");
#endif

#endif // MSM_PROBE_INTERFACE_H
