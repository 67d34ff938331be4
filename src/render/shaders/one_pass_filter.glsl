// The one-pass filter (HPG 2017 §4): one dispatch reads the depth samples of a tile, turns each
// into moments and resolves them, applies the separable Gaussian horizontally and vertically in
// shared memory, encodes (Φ and quantization for the non-linear maps; the storage basis of the
// linear ones is already in the generated moments) and writes each texel once.
//
// Layout (docs/techniques.md, "One-pass filter"): a workgroup of 32 x 8 threads makes a block of
// 32 x 16 texels. Shared memory holds the resolved moments of the block plus an apron of the
// filter radius R (a specialization constant) as four float arrays (structure of arrays), tile
// rows of 32 + 2R floats. In every phase the 32 threads of a warp (subgroup) touch 32
// consecutive floats of one array: loading (linear index), the horizontal pass (one output row,
// 32 consecutive columns, reading 32 consecutive inputs per tap) and the vertical pass (one
// output row, 32 consecutive columns of the 32-wide horizontal result): no bank conflicts on
// 32-bank hardware, whatever R. The horizontal results wait in registers while the tile is
// overwritten with them, so shared memory is only the tile: (32 + 2R)(16 + 2R) x 16 bytes,
// 15 KiB for the default 9 taps (R = 4), within the 16 KiB every Vulkan device has.
#extension GL_GOOGLE_include_directive : require
#include "msm/techniques.h"
#include "frame.glsl"

layout(constant_id = 1) const int kRadius = 4; // taps = 2 kRadius + 1; frame.filter_weights
layout(local_size_x = 32, local_size_y = 8) in;

const int kThreads = 256;
const int kBlockW = 32;
const int kBlockH = 16;
const int kTileW = kBlockW + 2 * kRadius;
const int kTileH = kBlockH + 2 * kRadius;
const int kMaxRadius = 8;                                    // checked by the host
const int kHorizontalPerThread = (kBlockH + 2 * kMaxRadius) * kBlockW / kThreads; // 4

#define MSM_DEPTH_BINDING 1
#include "depth_map.glsl"
#ifdef MSM_NL32
layout(binding = 2) writeonly uniform uimage2D target;
#else
layout(binding = 2) writeonly uniform image2D target;
#endif

layout(push_constant) uniform Push { ImagePassPush pc; };

shared float s0[kTileW * kTileH];
shared float s1[kTileW * kTileH];
shared float s2[kTileW * kTileH];
shared float s3[kTileW * kTileH];

vec4 load_shared(int i) { return vec4(s0[i], s1[i], s2[i], s3[i]); }
void store_shared(int i, vec4 v) {
  s0[i] = v.x;
  s1[i] = v.y;
  s2[i] = v.z;
  s3[i] = v.w;
}

void main() {
  int index = int(gl_LocalInvocationIndex);
  ivec2 size = pc.size.xy;
  ivec2 origin = ivec2(gl_WorkGroupID.xy) * ivec2(kBlockW, kBlockH);

  // 1. Resolve the tile (block + apron), clamped to the edge as the three-pass blur is.
  for (int i = index; i < kTileW * kTileH; i += kThreads) {
    ivec2 p = clamp(origin - kRadius + ivec2(i % kTileW, i / kTileW), ivec2(0), size - 1);
    store_shared(i, resolved_texel(p).a);
  }
  barrier();

  // 2. Horizontal: every tile row, the block's 32 columns; results in registers.
  vec4 horizontal[kHorizontalPerThread];
  for (int j = 0; j < kHorizontalPerThread; ++j) {
    int i = index + j * kThreads;
    if (i >= kTileH * kBlockW) break;
    int row = i / kBlockW, column = i % kBlockW;
    vec4 sum = vec4(0.0f);
    for (int k = 0; k <= 2 * kRadius; ++k) sum += kernel_weight(k) * load_shared(row * kTileW + column + k);
    horizontal[j] = sum;
  }
  barrier();
  for (int j = 0; j < kHorizontalPerThread; ++j) {
    int i = index + j * kThreads;
    if (i >= kTileH * kBlockW) break;
    store_shared(i, horizontal[j]); // now rows of kBlockW floats
  }
  barrier();

  // 3. Vertical, encode, write: two output rows per thread.
  for (int r = int(gl_LocalInvocationID.y); r < kBlockH; r += 8) {
    int column = int(gl_LocalInvocationID.x);
    vec4 sum = vec4(0.0f);
    for (int k = 0; k <= 2 * kRadius; ++k) sum += kernel_weight(k) * load_shared((r + k) * kBlockW + column);
    ivec2 p = origin + ivec2(column, r);
    if (p.x >= size.x || p.y >= size.y) continue;
#ifdef MSM_NL32
    imageStore(target, p, uvec4(msm_nl32_encode(sum)));
#else
    imageStore(target, p, kTechnique == MSM_TECH_NL64 ? msm_nl64_encode(sum) : sum);
#endif
  }
}
