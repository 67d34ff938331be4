// The one-pass filter (HPG 2017 §4): one dispatch reads the depth samples of a strip, turns each
// into moments and resolves them, applies the separable Gaussian horizontally and vertically,
// encodes (Φ and quantization for the non-linear maps; the storage basis of the linear ones is
// already in the generated moments) and writes each texel once.
//
// Layout (docs/techniques.md, "One-pass filter"): a workgroup of 32 threads makes a strip of
// 32 kColumns x 128 texels; thread i owns the kColumns adjacent columns [i kColumns, (i + 1)
// kColumns) of the strip and walks down them with the workgroup, kStep rows per step. Each step:
//  1. resolves kStep new tile rows: every thread its own columns (kept in registers as well), the
//     2R apron texels of those rows shared among the threads; all into `tile` in shared memory;
//  2. filters horizontally: each own column's 2R + 1 taps are the thread's own registers and the
//     2R neighbouring texels from `tile` (shared memory is read 2R / kColumns times per texel);
//  3. filters vertically in registers: each thread keeps, per own column, the last 2R + 1
//     horizontally filtered rows (`window`, shifted by one row per row: after unrolling a renaming,
//     no copies), and writes the output row whose 2R + 1 rows are all there.
// A texel is resolved (32 kColumns + 2R) / (32 kColumns) x (128 + 2R) / 128 times (1.13 at 9 taps,
// 1.25 at 15, kColumns = 4). Same arithmetic, same order as the three-pass filter: horizontal
// sums over k = 0 .. 2R, then vertical over k = 0 .. 2R. The radius and kColumns are
// specialization constants, so every loop below except the walk unrolls.
#extension GL_GOOGLE_include_directive : require
#include "msm/techniques.h"
#define MSM_LIGHT_BINDING MSM_BINDING_ONE_PASS_LIGHTS
#include "frame.glsl"

layout(constant_id = MSM_SPEC_FILTER_RADIUS) const int kRadius = 4;  // taps = 2 kRadius + 1; frame.filter_weights
layout(constant_id = MSM_SPEC_FILTER_COLUMNS) const int kColumns = 4; // adjacent columns per thread
layout(constant_id = MSM_SPEC_FILTER_SAMPLES) const int kSamples = 1; // MSAA samples per texel, = frame.kernel.y
// With cascades each layer filters with its own kernel (LightUniforms::kernel of layer pc.size.w:
// the first cascade's width in world units, msm/cascade.h; 0 beyond its radius), from
// msm/filter.h as the host computes the frame's; without, the frame's (kernel_weight).
layout(constant_id = MSM_SPEC_CASCADES) const bool kCascades = false;
#define MSM_RESOLVE_SAMPLES kSamples
layout(local_size_x = 32) in;

const int kThreads = 32;
const int kTaps = 2 * kRadius + 1;
const int kStep = 4;                      // tile rows per step (one barrier pair)
const int kStripW = kThreads * kColumns;  // output columns per workgroup
const int kStripH = 128;                  // output rows per workgroup
const int kTileW = kStripW + 2 * kRadius; // with the horizontal apron
const int kApron = kStep * 2 * kRadius;   // apron texels per step
const int kApronRounds = (kApron + kThreads - 1) / kThreads;

#define MSM_DEPTH_BINDING MSM_BINDING_ONE_PASS_DEPTH
#include "depth_map.glsl"
#ifdef MSM_NL32
layout(binding = MSM_BINDING_ONE_PASS_TARGET) writeonly uniform uimage2D target;
#else
layout(binding = MSM_BINDING_ONE_PASS_TARGET) writeonly uniform image2D target;
#endif

layout(push_constant) uniform Push { ImagePassPush pc; };

shared vec4 tile[kStep * kTileW]; // the step's resolved rows, tile column j at [row kTileW + j]

void main() {
  int thread = int(gl_LocalInvocationID.x);
  ivec2 size = pc.size.xy;
  // Tile row t is map row origin.y - kRadius + t, tile column j map column origin.x - kRadius + j
  // (both clamped to the edge, as the three-pass blur is); output row o is tile row o + 2R.
  ivec2 origin = ivec2(gl_WorkGroupID.xy) * ivec2(kStripW, kStripH);
  int rows = min(kStripH, size.y - origin.y);
  int first = kRadius + thread * kColumns; // tile column of the thread's first own column
  vec4 window[kColumns][kTaps];            // [c][k]: horizontal row t - 2R + k of own column c
  float weights[kTaps];
  vec4 kernel = kCascades ? lights[pc.size.w].kernel : vec4(0.0f);
  for (int k = 0; k < kTaps; ++k)
    weights[k] = kCascades ? msm_filter_weight_at(k - kRadius, int(kernel.y), kernel.x) : kernel_weight(k);
  for (int c = 0; c < kColumns; ++c)
    for (int k = 0; k < kTaps; ++k) window[c][k] = vec4(0.0f);
  for (int t0 = 0; t0 < rows + 2 * kRadius; t0 += kStep) {
    // 1. Resolve tile rows [t0, t0 + kStep).
    vec4 own[kStep][kColumns];
    for (int s = 0; s < kStep; ++s) {
      int y = clamp(origin.y - kRadius + t0 + s, 0, size.y - 1);
      for (int c = 0; c < kColumns; ++c) {
        own[s][c] = resolved_texel(ivec2(min(origin.x - kRadius + first + c, size.x - 1), y)).a;
        tile[s * kTileW + first + c] = own[s][c];
      }
    }
    for (int r = 0; r < kApronRounds; ++r) {
      int i = r * kThreads + thread; // apron texel i: row i / 2R, left R then right R columns
      if (i < kApron) {
        int a = i % (2 * kRadius), s = i / (2 * kRadius);
        int j = a < kRadius ? a : kStripW + a;
        ivec2 p = clamp(origin - kRadius + ivec2(j, t0 + s), ivec2(0), size - 1);
        tile[s * kTileW + j] = resolved_texel(p).a;
      }
    }
    barrier();
    for (int s = 0; s < kStep; ++s) {
      // 2. Horizontal: taps [first + c - R, first + c + R] of the row; own columns from registers.
      vec4 row[kColumns + 2 * kRadius];
      for (int j = 0; j < kRadius; ++j) {
        row[j] = tile[s * kTileW + first - kRadius + j];
        row[kRadius + kColumns + j] = tile[s * kTileW + first + kColumns + j];
      }
      for (int c = 0; c < kColumns; ++c) row[kRadius + c] = own[s][c];
      // 3. Vertical over the window, once it holds the 2R + 1 rows of output row o.
      int o = t0 + s - 2 * kRadius;
      for (int c = 0; c < kColumns; ++c) {
        vec4 sum = vec4(0.0f);
        for (int k = 0; k < kTaps; ++k) sum += weights[k] * row[c + k];
        for (int k = 0; k + 1 < kTaps; ++k) window[c][k] = window[c][k + 1];
        window[c][kTaps - 1] = sum;
        sum = vec4(0.0f);
        for (int k = 0; k < kTaps; ++k) sum += weights[k] * window[c][k];
        ivec2 p = origin + ivec2(first - kRadius + c, o);
        if (o >= 0 && o < rows && p.x < size.x) {
#ifdef MSM_NL32
          imageStore(target, p, uvec4(msm_nl32_encode(sum)));
#else
          imageStore(target, p, kTechnique == MSM_TECH_NL64 ? msm_nl64_encode(sum) : sum);
#endif
        }
      }
    }
    barrier(); // the next step overwrites the tile
  }
}
