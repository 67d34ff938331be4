// Forward shading (Lambert + constant ambient) with the technique's shadow, tone mapping and
// sRGB output, plus the shadow buffer (visibility of the visible surface) for error measurement.
// The including shader defines shadow_intensity() for its family of techniques.
#include "msm/techniques.h"
#include "frame.glsl"

layout(binding = 1) uniform sampler2D albedo_texture;
layout(binding = 5) uniform sampler2D opacity_texture; // R8: used where object.flags.z != 0
layout(push_constant) uniform Push { ObjectPush object; };

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;

layout(location = 0) out vec4 out_color;  // tone mapped; the attachment is sRGB
layout(location = 1) out vec4 out_shadow; // rgb: light visibility per colour channel, a: 1 (a surface)

// Where a fragment looks up the shadow map: t in texel-centre coordinates (texel i covers
// [i - 0.5, i + 0.5)), z its depth in [0,1], and the receiver plane's depth per texel along x and
// y (from the surface normal: PCF and the plain map compare against the plane, not one depth).
struct ShadowLookup {
  vec2 t;
  float z;
  vec2 depth_per_texel;
};

float shadow_intensity(ShadowLookup s);
#ifdef MSM_COLOURED_SHADOWS
// Per colour channel (coloured translucency: the including shader defines it with the macro).
vec3 shadow_intensity_rgb(ShadowLookup s);
#endif

// Narkowicz's fit of the ACES filmic curve (as msm::image::ToneCurve::aces).
vec3 tone_map(vec3 x) { return clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f); }

#include "alpha_test.glsl"

void main() {
  if (!alpha_test_passes(object, opacity_texture, texcoord)) discard; // cut-outs (alpha mask)
  vec3 n = normalize(world_normal);
  if (!gl_FrontFacing) n = -n; // only double-sided materials show back faces (culling)
  vec3 l = frame.towards_light.xyz;
  float n_dot_l = dot(n, l);

  vec3 visibility = vec3(0.0f); // surfaces turned away from the light are in their own shadow
  if (n_dot_l > 0.0f) {
    // Normal offset: more at grazing light, where depth varies fastest across a texel.
    vec3 p = world_position + n * (frame.shadow_map.z * (1.0f - n_dot_l));
    vec4 clip = frame.light_view_projection * vec4(p, 1.0f);
    vec3 nc = mat3(frame.light_normal_matrix) * n;
    ShadowLookup s;
    s.t = (clip.xy * 0.5f + 0.5f) * frame.shadow_map.x - 0.5f;
    s.z = clip.z - frame.shadow_map.w;
    // The plane n_c . (dx, dy, dz) = 0 in clip space; one texel is 2 / size clip units.
    float slope_limit = MSM_MAX_RECEIVER_DEPTH_SLOPE;
    s.depth_per_texel = abs(nc.z) > 1e-6f
                            ? clamp(-vec2(nc.x, nc.y) / nc.z * (2.0f * frame.shadow_map.y), -slope_limit, slope_limit)
                            : vec2(0.0f);
    bool inside = all(greaterThanEqual(clip.xy, vec2(-1.0f))) && all(lessThanEqual(clip.xy, vec2(1.0f))) &&
                  clip.z <= 1.0f;
#ifdef MSM_COLOURED_SHADOWS
    vec3 shadow = inside ? shadow_intensity_rgb(s) : vec3(0.0f);
#else
    vec3 shadow = vec3(inside ? shadow_intensity(s) : 0.0f);
#endif
    if (frame.shading.x < 1.0f)
      shadow = vec3(msm_overdarken(shadow.x, frame.shading.x), msm_overdarken(shadow.y, frame.shading.x),
                    msm_overdarken(shadow.z, frame.shading.x));
    visibility = 1.0f - shadow;
  }

  vec3 albedo = object.albedo_opacity.rgb;
  if (object.flags.x != 0) albedo *= texture(albedo_texture, texcoord).rgb;
  vec3 radiance = albedo * (frame.irradiance.rgb * (max(n_dot_l, 0.0f) * visibility / MSM_PI) + frame.irradiance.a);
  // Alpha: the surface's opacity (translucent objects blend over the opaque image).
  float opacity = object.albedo_opacity.a;
  if (object.flags.z != 0) opacity *= texture(opacity_texture, texcoord).x;
  out_color = vec4(tone_map(radiance * frame.shading.y), opacity);
  out_shadow = vec4(visibility, 1.0f);
}
