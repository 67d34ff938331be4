// One direction of the separable Gaussian blur of a moment image: horizontal when pc.size.z == 0,
// vertical otherwise. The kernel is compiled in (specialization constants, MSM_BLUR_SPEC_ID in
// msm/render/frame.h): the centre fetch, then kPairs fetches on each side at fixed offsets and
// weights, unrolled. With a linear sampler each side fetch is one bilinear pair of taps
// (msm_filter_pair_offset in msm/filter.h); with a point sampler the host passes the single taps
// at integer offsets. Clamp-to-edge comes from the sampler. No test for non-finite texels: the
// resolve writes finite moments only (RenderTest.ResolveWritesFiniteMoments).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/frame.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2D source;
layout(binding = 1) writeonly uniform image2D target;

layout(push_constant) uniform Push { ImagePassPush pc; };

layout(constant_id = MSM_BLUR_SPEC_ID) const int kPairs = 2;
layout(constant_id = MSM_BLUR_SPEC_ID + 1) const float kCentre = 1.0f;
#define MSM_BLUR_PAIR(I)                                                                                           \
  layout(constant_id = MSM_BLUR_SPEC_ID + 1 + I) const float kOffset##I = 0.0f;                                   \
  layout(constant_id = MSM_BLUR_SPEC_ID + 1 + MSM_BLUR_MAX_PAIRS + I) const float kWeight##I = 0.0f;
MSM_BLUR_PAIR(1)
MSM_BLUR_PAIR(2)
MSM_BLUR_PAIR(3)
MSM_BLUR_PAIR(4)
MSM_BLUR_PAIR(5)
MSM_BLUR_PAIR(6)
MSM_BLUR_PAIR(7)
MSM_BLUR_PAIR(8)
MSM_BLUR_PAIR(9)
MSM_BLUR_PAIR(10)
MSM_BLUR_PAIR(11)
MSM_BLUR_PAIR(12)
MSM_BLUR_PAIR(13)
MSM_BLUR_PAIR(14)
MSM_BLUR_PAIR(15)
MSM_BLUR_PAIR(16)

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.size.x || p.y >= pc.size.y) return;
  vec2 texel = 1.0f / vec2(pc.size.xy);
  vec2 centre = (vec2(p) + 0.5f) * texel;
  vec2 step = pc.size.z == 0 ? vec2(texel.x, 0.0f) : vec2(0.0f, texel.y);
  vec4 sum = kCentre * textureLod(source, centre, 0.0f);
  // Dead after specialization beyond kPairs: the driver keeps kPairs straight-line fetch pairs.
#define MSM_BLUR_FETCH(I)                                                                                          \
  if (kPairs >= I)                                                                                                 \
    sum += kWeight##I * (textureLod(source, centre - kOffset##I * step, 0.0f) +                                    \
                         textureLod(source, centre + kOffset##I * step, 0.0f));
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
  imageStore(target, p, sum);
}
