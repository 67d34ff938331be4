// Moment resolve: the technique's filterable channels for every depth sample of a texel,
// averaged (the MSAA resolve is a box filter, linear like everything before storage), then
// written in the storage basis the format holds (generation already applies θ2/θ4/Θ4*/Θ6*).
// Non-finite depths cannot come from the rasterizer; clamping keeps them out anyway.
#include "msm/techniques.h"
#include "frame.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// The mean of the front- and back-face depth (Kneiphof §4.2.3; FrameConfig::front_back).
layout(constant_id = MSM_SPEC_FRONT_BACK) const bool kFrontBack = false;
#define MSM_DEPTH_BINDING MSM_BINDING_RESOLVE_DEPTH
#define MSM_BACK_DEPTH_BINDING MSM_BINDING_RESOLVE_BACK_DEPTH
#include "depth_map.glsl"
layout(binding = MSM_BINDING_RESOLVE_MOMENTS0) writeonly uniform image2D moments0;
layout(binding = MSM_BINDING_RESOLVE_MOMENTS1) writeonly uniform image2D moments1; // second half of 6MSM; else moments0 again

layout(push_constant) uniform Push { ImagePassPush pc; };

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.size.x || p.y >= pc.size.y) return;
  if (msm_technique_is_cssm(kTechnique)) { // every tile of the texel's samples, averaged (cssm.h)
    int frequencies = msm_technique_cssm_frequencies(kTechnique), samples = frame.kernel.y;
    for (int tile = 0; tile < msm_cssm_tiles(frequencies); ++tile) {
      vec4 sum = vec4(0.0f);
      for (int s = 0; s < samples; ++s) sum += msm_cssm_generate(msm_saturate(depth_sample(p, s)), tile, frequencies);
      imageStore(moments0, p + ivec2(0, tile * pc.size.y), sum / float(samples));
    }
    return;
  }
  MsmTexel t = resolved_texel(p);
  vec4 a = t.a, b = t.b;
  if (kSplitRG) {
    imageStore(moments0, p, vec4(a.x, a.y, 0.0f, 0.0f));
    imageStore(moments1, p, vec4(a.z, a.w, 0.0f, 0.0f));
  } else {
    imageStore(moments0, p, a);
    if (msm_technique_is_six_moments(kTechnique)) imageStore(moments1, p, b);
  }
}
