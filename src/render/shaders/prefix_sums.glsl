// Transmittance-weighted prefix sums along the rows of the rectified map (JCGT §5.1.1), in one of
// two schemes (the specialization constant kRowSweep, RenderSettings::prefix_sums):
// - the row sweep: every thread of a group of 8 x 8 takes a row (64 rows per group) and walks it
//   once, reading and writing each texel once;
// - the scheme of Appendix C: eight rows per group and eight threads per row; walking the row in
//   blocks of eight texels, every thread sums the whole row (eight times the reads, which the
//   texture cache absorbs) and writes the one normalized prefix sum of its column in the block, so
//   that the writes of a block are coalesced.
// Both add the same terms in the same order. Weights w(j, v) and Δ(v) are rectification.h's.
// The including file defines the storage: MSM_PREFIX_FORMAT0 (and, with MSM_SIX_MOMENTS, the second
// image's MSM_PREFIX_FORMAT1 and MSM_PREFIX_ODD_EVEN for two RGB10A2 images holding the odd and the
// even moments; otherwise (odd, even.x) and (even.y, even.z) as in the rectified map). With MSM_CSM
// both are arrays of eight layers per light (the convolution shadow map's 32 coefficients), one
// layer per dispatch z. One dispatch per light (the push constant's size.z: its rectification
// rects[light]; CSM: its layers 8 light + t; the others bind the light's layer).
// Transmittance layers (rectification.h): size.w = K prefix sums of the light's map, with the steps
// Δ_k (K = 1: the paper's Δ(v) per row); dispatch z = k (CSM: 8 k + t) writes output layer
// K light + k (CSM: 8 (K light + k) + t).
// A spot light's rows (rects[light].spot) weigh their light rays at the row's γ (texel_weight).
#include "msm/render/frame.h"
#include "msm/render/rectification_uniforms.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = MSM_BINDING_PREFIX_RECTS) readonly buffer RectificationBlock { RectificationUniforms rects[]; };
layout(push_constant) uniform Push { ImagePassPush pass; }; // size.z: the light
layout(binding = MSM_BINDING_PREFIX_TARGET, MSM_PREFIX_FORMAT0) uniform writeonly image2DArray prefix_sums; // every light's layers
#ifdef MSM_CSM
layout(binding = MSM_BINDING_PREFIX_SOURCE) uniform sampler2DArray rectified; // float coefficients, texelFetch only
#define kTerm (int(gl_WorkGroupID.z) % MSM_CSM_MAX_TEXELS)
#define kLayer (int(gl_WorkGroupID.z) / MSM_CSM_MAX_TEXELS)
#define MSM_TEXEL(x, y) ivec3(x, y, MSM_CSM_MAX_TEXELS * pass.size.z + kTerm)
#define MSM_OUT(x, y) ivec3(x, y, MSM_CSM_MAX_TEXELS * (pass.size.w * pass.size.z + kLayer) + kTerm)
#else
layout(binding = MSM_BINDING_PREFIX_SOURCE) uniform sampler2D rectified; // float moments, texelFetch only
#define kLayer int(gl_WorkGroupID.z)
#define MSM_TEXEL(x, y) ivec2(x, y)
#define MSM_OUT(x, y) ivec3(x, y, pass.size.w * pass.size.z + kLayer)
#endif
#ifdef MSM_SIX_MOMENTS
layout(binding = MSM_BINDING_PREFIX_SOURCE1) uniform sampler2D rectified1;
layout(binding = MSM_BINDING_PREFIX_TARGET1, MSM_PREFIX_FORMAT1) uniform writeonly image2DArray prefix_sums1;
#endif

layout(constant_id = MSM_PREFIX_ROWS_SPEC_ID) const bool kRowSweep = true;
// Whether some light of the frame is a spot light (FrameConfig::spot_lights): a constant, so that
// frames of directional lights only compile no spot path.
layout(constant_id = MSM_SPEC_SPOT_LIGHTS) const bool kSpotLights = false;

void store_prefix_sum(int x, int row, vec4 mine, vec4 mine1) {
  ivec3 texel = MSM_OUT(x, row);
#if defined(MSM_CSM)
  imageStore(prefix_sums, texel, mine);
#elif defined(MSM_SIX_MOMENTS) && defined(MSM_PREFIX_ODD_EVEN)
  imageStore(prefix_sums, texel, vec4(mine.x, mine.y, mine.z, 0.0f));
  imageStore(prefix_sums1, texel, vec4(mine.w, mine1.x, mine1.y, 0.0f));
#else
  imageStore(prefix_sums, texel, mine);
#ifdef MSM_SIX_MOMENTS
  imageStore(prefix_sums1, texel, mine1);
#endif
#endif
}

// A spot light's rows (rectification.h's spot section) weigh the light ray ψ of texel x by the
// phase, the cone and the transmittance at the row's γ (msm_spot_prefix_sum_weight); main sets these.
bool spot_light = false;
RectificationFrame spot_frame;
RectifiedBounds spot_bounds;
float spot_row_v = 0.0f, spot_row_gamma = 0.0f;

// w(x, v): a directional light's transmittance integral over the texel's segment, a spot light's
// weight of its light ray (floored, so that a row wholly outside the cone reads the mean of its
// texels, never 0 / 0; what it scatters is 0 there anyway).
float texel_weight(int x, float extinction, float delta) {
  if (!(kSpotLights && spot_light)) return msm_prefix_sum_weight(extinction, delta, float(x));
  RectificationUniforms rect = rects[pass.size.z];
  vec2 uv = vec2((float(x) + 0.5f) / rect.map.x, spot_row_v);
  float cone = msm_spot_cone(dot(msm_spot_light_ray_direction(spot_frame, spot_bounds, uv), vec3(rect.spot_axis)),
                             rect.spot.z, rect.spot.w);
  float w = msm_spot_prefix_sum_weight(rect.spot.x, uv.x * spot_bounds.r_max, spot_row_gamma, extinction, rect.spot.y,
                                       cone);
  return max(w, 1e-30f);
}

// Adds texel x of the row with its weight w(x, v) to the running sums (both schemes, in order).
void add_texel(int x, int row, float extinction, float delta, inout vec4 sum, inout vec4 sum1, inout float weight_sum) {
  float w = texel_weight(x, extinction, delta);
  sum += w * texelFetch(rectified, MSM_TEXEL(x, row), 0);
#ifdef MSM_SIX_MOMENTS
  sum1 += w * texelFetch(rectified1, ivec2(x, row), 0);
#endif
  weight_sum += w;
}

void main() {
  RectificationUniforms rect = rects[pass.size.z];
  ivec2 size = ivec2(int(rect.map.x), int(rect.map.y));
  int rows_per_group = kRowSweep ? 64 : 8;
  int row = int(gl_WorkGroupID.x) * rows_per_group + int(gl_LocalInvocationID.y) * (kRowSweep ? 8 : 1) +
            (kRowSweep ? int(gl_LocalInvocationID.x) : 0);
  int column = int(gl_LocalInvocationID.x);
  if (row >= size.y) return;
  RectifiedBounds b = msm_rectified_bounds_of(rect);
  float extinction = rect.map.w;
  spot_light = msm_rectification_is_spot(rect);
  spot_frame = msm_rectification_frame_of(rect);
  spot_bounds = b;
  spot_row_v = (float(row) + 0.5f) / float(size.y);
  spot_row_gamma = msm_spot_row_gamma(b, spot_row_v);
  float delta = msm_prefix_sum_step(b, (float(row) + 0.5f) / float(size.y), float(size.x), extinction, float(kLayer),
                                    float(pass.size.w));
  vec4 sum = vec4(0.0f), sum1 = vec4(0.0f);
  float weight_sum = 0.0f;
  if (kRowSweep) {
    for (int x = 0; x < size.x; ++x) {
      add_texel(x, row, extinction, delta, sum, sum1, weight_sum);
      store_prefix_sum(x, row, sum / weight_sum, sum1 / weight_sum);
    }
    return;
  }
  for (int x0 = 0; x0 < size.x; x0 += 8) {
    vec4 mine = vec4(0.0f), mine1 = vec4(0.0f);
    for (int k = 0; k < 8 && x0 + k < size.x; ++k) {
      add_texel(x0 + k, row, extinction, delta, sum, sum1, weight_sum);
      if (k == column) {
        mine = sum / weight_sum;
        mine1 = sum1 / weight_sum;
      }
    }
    if (x0 + column < size.x) store_prefix_sum(x0 + column, row, mine, mine1);
  }
}
