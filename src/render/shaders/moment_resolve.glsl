// Moment resolve: the technique's filterable channels for every depth sample of a texel,
// averaged (the MSAA resolve is a box filter, linear like everything before storage), then
// written in the storage basis the format holds (generation already applies θ2/θ4/Θ4*/Θ6*).
// Non-finite depths cannot come from the rasterizer; clamping keeps them out anyway.
#include "msm/techniques.h"
#include "frame.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

#ifdef MSM_SINGLE_SAMPLE
layout(binding = 1) uniform sampler2D depth_map;
#else
layout(binding = 1) uniform sampler2DMS depth_map;
#endif
layout(binding = 2) writeonly uniform image2D moments0;
layout(binding = 3) writeonly uniform image2D moments1; // second half of 6MSM; else moments0 again

layout(push_constant) uniform Push { ImagePassPush pc; };

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.size.x || p.y >= pc.size.y) return;
  vec4 params = frame.technique_params;
  int samples = frame.kernel.y;
  vec4 a = vec4(0.0f), b = vec4(0.0f);
  for (int s = 0; s < samples; ++s) {
#ifdef MSM_SINGLE_SAMPLE
    float depth = texelFetch(depth_map, p, 0).x;
#else
    float depth = texelFetch(depth_map, p, s).x;
#endif
    depth = msm_saturate(depth); // NaN -> 0, never into the moments
    MsmTexel t = msm_technique_generate(kTechnique, depth, params);
    a += t.a;
    b += t.b;
  }
  float inv = 1.0f / float(samples);
  a *= inv;
  b *= inv;
  if (kSplitRG) {
    imageStore(moments0, p, vec4(a.x, a.y, 0.0f, 0.0f));
    imageStore(moments1, p, vec4(a.z, a.w, 0.0f, 0.0f));
  } else {
    imageStore(moments0, p, a);
    if (kTechnique == MSM_TECH_MSM6_192 || kTechnique == MSM_TECH_MSM6_96) imageStore(moments1, p, b);
  }
}
