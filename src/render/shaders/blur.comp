// One direction of the separable Gaussian blur of a moment image: horizontal when pc.size.z == 0,
// vertical otherwise. The centre fetch, then kPairs fetches on each side (a specialization
// constant, MSM_BLUR_SPEC_ID in msm/render/frame.h: the widest kernel of the frame), unrolled, at
// the offsets and with the weights of the layer's kernel (kernels[pc.size.w], BlurKernel: a
// cascade's is narrower in its texels than the first cascade's, the same in world units; its
// pairs beyond its own radius weigh 0). With a linear sampler each side fetch is one bilinear pair
// of taps (msm_filter_pair_offset in msm/filter.h); with a point sampler the pair's two texels at
// integer offsets. Clamp-to-edge comes from the sampler. No test for non-finite texels: the
// resolve writes finite moments only (RenderTest.ResolveWritesFiniteMoments).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/frame.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = MSM_BINDING_BLUR_SOURCE) uniform sampler2D source;
layout(binding = MSM_BINDING_BLUR_TARGET) writeonly uniform image2D target;
layout(binding = MSM_BINDING_BLUR_TARGET_MIP1) writeonly uniform image2D target_mip1; // kMip1

layout(push_constant) uniform Push { ImagePassPush pc; };

layout(std430, binding = MSM_BINDING_BLUR_KERNELS) readonly buffer Kernels { BlurKernel kernels[]; };

layout(constant_id = MSM_BLUR_SPEC_ID) const int kPairs = 2;

// Value i of the layer's kernel: 0 the centre weight, 2 j - 1 pair j's offset, 2 j its weight.
float kernel_value(int i) { return kernels[pc.size.w].values[i / 4][i % 4]; }

// false: each pair as its two texels, point fetches with the weights W (1 - f) and W f, f the
// fraction of the pair's offset: exact, for the 32-bit float maps (a bilinear fetch's fraction is
// only as precise as the coordinate, ~1e-5 of a texel at 200 texels, 2e-4 at 2048).
layout(constant_id = MSM_BLUR_SPEC_ID + 2 + 2 * MSM_BLUR_MAX_PAIRS) const bool kBilinear = true;
layout(constant_id = MSM_BLUR_SPEC_ID + 3 + 2 * MSM_BLUR_MAX_PAIRS) const bool kMip1 = false;

ivec2 g_p, g_step, g_last;
vec4 point_pair(int inner, float offset, float weight) {
  float f = offset - float(inner);
  return weight * (1.0f - f) *
             (texelFetch(source, clamp(g_p - inner * g_step, ivec2(0), g_last), 0) +
              texelFetch(source, clamp(g_p + inner * g_step, ivec2(0), g_last), 0)) +
         weight * f *
             (texelFetch(source, clamp(g_p - (inner + 1) * g_step, ivec2(0), g_last), 0) +
              texelFetch(source, clamp(g_p + (inner + 1) * g_step, ivec2(0), g_last), 0));
}

// Pair j's two fetches, weighted, at its offset from the centre (uv) along step (one texel in uv).
vec4 pair_fetch(int j, vec2 centre, vec2 step) {
  float offset = kernel_value(2 * j - 1), weight = kernel_value(2 * j);
  if (!kBilinear) return point_pair(2 * j - 1, offset, weight);
  return weight * (textureLod(source, centre - offset * step, 0.0f) + textureLod(source, centre + offset * step, 0.0f));
}

vec4 blur_at(ivec2 p) {
  vec2 texel = 1.0f / vec2(pc.size.xy);
  vec2 centre = (vec2(p) + 0.5f) * texel;
  vec2 step = pc.size.z == 0 ? vec2(texel.x, 0.0f) : vec2(0.0f, texel.y);
  g_p = p;
  g_step = pc.size.z == 0 ? ivec2(1, 0) : ivec2(0, 1);
  g_last = pc.size.xy - 1;
  vec4 sum = kernel_value(0) * texelFetch(source, p, 0); // on the texel: no filtering to pay for
  // Dead after specialization beyond kPairs: the driver keeps kPairs straight-line fetch pairs.
#define MSM_BLUR_FETCH(I)                                                                                          \
  if (kPairs >= I) sum += pair_fetch(I, centre, step);
  MSM_BLUR_FETCH(1)
  MSM_BLUR_FETCH(2)
  MSM_BLUR_FETCH(3)
  MSM_BLUR_FETCH(4)
  MSM_BLUR_FETCH(5)
  MSM_BLUR_FETCH(6)
  MSM_BLUR_FETCH(7)
  MSM_BLUR_FETCH(8)
  MSM_BLUR_FETCH(9)
  MSM_BLUR_FETCH(10)
  MSM_BLUR_FETCH(11)
  MSM_BLUR_FETCH(12)
  MSM_BLUR_FETCH(13)
  MSM_BLUR_FETCH(14)
  MSM_BLUR_FETCH(15)
  MSM_BLUR_FETCH(16)
  return sum;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (!kMip1) {
    if (p.x >= pc.size.x || p.y >= pc.size.y) return;
    imageStore(target, p, blur_at(p));
    return;
  }
  // p: a texel of mip 1 (the host makes sure the size is even).
  if (2 * p.x >= pc.size.x || 2 * p.y >= pc.size.y) return;
  vec4 sum = vec4(0.0f);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      ivec2 q = 2 * p + ivec2(x, y);
      vec4 v = blur_at(q);
      imageStore(target, q, v);
      sum += v;
    }
  imageStore(target_mip1, p, 0.25f * sum);
}
