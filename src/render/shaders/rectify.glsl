// Resampling of the first light's shadow map into the rectified map of prefiltered single
// scattering (JCGT §5.1.1, §5.2; rectification.h): per rectified texel, the light ray at (r, φ) is
// looked up in the light's depth map (without filtering: the nearest texel, sample 0), its depth
// mapped to the rectified depth π − θ and turned into the technique's moments in its storage basis
// (Θ4*; with MSM_SIX_MOMENTS Θ6* over two images: (odd, even.x) and (even.y, even.z)), written as
// float for the prefix sums. A light ray outside the map, or over a texel without
// a caster, gets the farthest rectified depth: nothing on it shadows any view ray.
#include "msm/render/rectification_uniforms.h"
#include "msm/quantize.h"
#define MSM_LIGHT_BINDING 2
#include "frame.glsl"
#define MSM_DEPTH_BINDING 3
#include "depth_map.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std140, binding = 1) uniform RectificationBlock { RectificationUniforms rect; };
layout(binding = 4, rgba32f) uniform writeonly image2D rectified;
#ifdef MSM_SIX_MOMENTS
layout(binding = 5, rgba32f) uniform writeonly image2D rectified1;
#endif

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(int(rect.map.x), int(rect.map.y));
  if (texel.x >= size.x || texel.y >= size.y) return;
  RectificationFrame f = msm_rectification_frame_of(rect);
  RectifiedBounds b = msm_rectified_bounds_of(rect);
  vec2 uv = (vec2(texel) + 0.5f) / vec2(size);
  vec3 p = msm_rectified_light_ray_point(f, b, uv);
  float r = msm_rectified_r_phi(b, uv).x;
  vec4 clip = lights[0].view_projection * vec4(p, 1.0f);
  // The map's depth d lies at rectification z = extent (d − d(p)) on this light ray.
  vec2 depth_to_z = vec2(rect.map.z, -clip.z * rect.map.z);
  TwoDepths d = TwoDepths(vec2(1.0f), vec2(1.0f, 0.0f));
  bool inside = all(greaterThanEqual(vec2(clip.x, clip.y), vec2(-1.0f))) &&
                all(lessThanEqual(vec2(clip.x, clip.y), vec2(1.0f)));
  if (inside) {
    int map = int(frame.shadow_map.x);
    ivec2 t = clamp(ivec2(floor((vec2(clip.x, clip.y) * 0.5f + 0.5f) * frame.shadow_map.x)), ivec2(0), ivec2(map - 1));
    float depth = depth_sample(t, 0);
    if (depth < 1.0f) d = msm_rectified_one_depth(b, r, depth_to_z, depth);
  }
#ifdef MSM_SIX_MOMENTS
  Moments6 m = msm_theta6_star(msm_rectified_moments6(d));
  imageStore(rectified, texel, vec4(m.odd, m.even.x));
  imageStore(rectified1, texel, vec4(m.even.y, m.even.z, 0.0f, 0.0f));
#else
  imageStore(rectified, texel, msm_theta4_star(msm_rectified_moments4(d)));
#endif
}
