// The one-pass filter (HPG 2017 §4): one dispatch reads the depth samples of a strip, turns each
// into moments and resolves them, applies the separable Gaussian horizontally and vertically in
// shared memory, encodes (Φ and quantization for the non-linear maps; the storage basis of the
// linear ones is already in the generated moments) and writes each texel once.
//
// Layout (docs/techniques.md, "One-pass filter"): a workgroup of 32 x 4 threads makes a strip of
// 32 x 128 texels, walking down it four rows at a time. Each step resolves four new rows of the
// tile (with the horizontal apron of the filter radius R, a specialization constant) into `res`,
// filters them horizontally into a ring buffer of rows, and filters vertically the four output rows
// whose 2R + 1 horizontal rows are all in the ring. A texel is resolved (32 + 2R) / 32 times
// horizontally and (128 + 4 ceil(R / 2)) / 128 times vertically: 1.33 in all at 9 taps, 1.62 at
// 15 (a 32 x 16 tile with its apron in every direction: 1.88 and 2.7). Shared memory is four float
// arrays per buffer (structure of arrays; a warp touches 32 consecutive floats in every phase):
// (4 (32 + 2R) + 32 ring rows) x 16 bytes, at most 13 KiB (R = 8), within the 16 KiB every Vulkan
// device has. Same arithmetic, same order as before: horizontal sums over k, then vertical.
#extension GL_GOOGLE_include_directive : require
#include "msm/techniques.h"
#include "frame.glsl"

layout(constant_id = 1) const int kRadius = 4; // taps = 2 kRadius + 1; frame.filter_weights
layout(local_size_x = 32, local_size_y = 4) in;

const int kThreads = 128;
const int kStripW = 32;
const int kStep = 4;                                          // rows per step
const int kStripH = 128;                                      // output rows per workgroup
const int kTileW = kStripW + 2 * kRadius;
const int kLag = (2 * kRadius + kStep - 1) / kStep;           // steps between a row's resolve and its output
const int kRingRows = kStep * (kLag + 1);                     // horizontal rows kept
const int kSteps = kStripH / kStep + kLag;

#define MSM_DEPTH_BINDING 1
#include "depth_map.glsl"
#ifdef MSM_NL32
layout(binding = 2) writeonly uniform uimage2D target;
#else
layout(binding = 2) writeonly uniform image2D target;
#endif

layout(push_constant) uniform Push { ImagePassPush pc; };

shared float r0[kStep * kTileW]; // resolved rows of the current step, with the horizontal apron
shared float r1[kStep * kTileW];
shared float r2[kStep * kTileW];
shared float r3[kStep * kTileW];
shared float h0[kRingRows * kStripW]; // horizontally filtered rows, tile row t at slot t % kRingRows
shared float h1[kRingRows * kStripW];
shared float h2[kRingRows * kStripW];
shared float h3[kRingRows * kStripW];

vec4 load_resolved(int i) { return vec4(r0[i], r1[i], r2[i], r3[i]); }
void store_resolved(int i, vec4 v) {
  r0[i] = v.x;
  r1[i] = v.y;
  r2[i] = v.z;
  r3[i] = v.w;
}
vec4 load_horizontal(int i) { return vec4(h0[i], h1[i], h2[i], h3[i]); }
void store_horizontal(int i, vec4 v) {
  h0[i] = v.x;
  h1[i] = v.y;
  h2[i] = v.z;
  h3[i] = v.w;
}

void main() {
  int index = int(gl_LocalInvocationIndex);
  int column = int(gl_LocalInvocationID.x), row = int(gl_LocalInvocationID.y);
  ivec2 size = pc.size.xy;
  // Tile row t is map row origin.y - kRadius + t; output row o is origin.y + o.
  ivec2 origin = ivec2(gl_WorkGroupID.xy) * ivec2(kStripW, kStripH);
  for (int step = 0; step < kSteps; ++step) {
    // 1. Resolve tile rows [step kStep, step kStep + kStep), clamped to the edge as the three-pass
    //    blur is.
    for (int i = index; i < kStep * kTileW; i += kThreads) {
      ivec2 p = clamp(origin - kRadius + ivec2(i % kTileW, step * kStep + i / kTileW), ivec2(0), size - 1);
      store_resolved(i, resolved_texel(p).a);
    }
    barrier();
    // 2. Horizontal: one row per thread row, the strip's 32 columns, into the ring.
    vec4 sum = vec4(0.0f);
    for (int k = 0; k <= 2 * kRadius; ++k) sum += kernel_weight(k) * load_resolved(row * kTileW + column + k);
    store_horizontal(((step * kStep + row) % kRingRows) * kStripW + column, sum);
    barrier();
    // 3. Vertical, encode, write the output rows whose tile rows are all filtered (the ring slots
    //    it reads are overwritten only after the next step's barrier).
    int first = (step - kLag) * kStep;
    if (first >= 0) {
      int o = first + row;
      sum = vec4(0.0f);
      for (int k = 0; k <= 2 * kRadius; ++k)
        sum += kernel_weight(k) * load_horizontal(((o + k) % kRingRows) * kStripW + column);
      ivec2 p = origin + ivec2(column, o);
      if (p.x < size.x && p.y < size.y) {
#ifdef MSM_NL32
        imageStore(target, p, uvec4(msm_nl32_encode(sum)));
#else
        imageStore(target, p, kTechnique == MSM_TECH_NL64 ? msm_nl64_encode(sum) : sum);
#endif
      }
    }
  }
}
