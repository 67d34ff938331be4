// Forward shading (Lambert + constant ambient, msm/shading.h) with the technique's shadow of every
// light of the frame, tone mapping and sRGB output, plus the shadow buffer (visibility of the
// visible surface) for error measurement. The including shader defines shadow_intensity() for its
// family of techniques; it reads layer `shadow_layer` of the shadow-map arrays (the light being
// evaluated).
#include "msm/cube_face.h"
#include "msm/cascade.h"
#include "msm/footprint.h"
#include "msm/local_light.h"
#include "msm/shading.h"
#include "msm/techniques.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SHADING_LIGHTS
#include "frame.glsl"
#include "light_loop.glsl"
// Scattering techniques: the colour attachment takes linear radiance (before exposure and tone
// mapping), which the scattering pass composites with the medium's in-scattering.
layout(constant_id = MSM_SPEC_LINEAR_RADIANCE) const bool kLinearRadiance = false;
// False where no draw of the frame has an albedo or opacity texture (FrameConfig::textured_draws):
// lavapipe runs both sides of the branches on the draw's flags, so untextured draws paid for the
// fetches (a GPU skips them either way).
layout(constant_id = MSM_SPEC_TEXTURED_DRAWS) const bool kTexturedDraws = true;
// Whether some light of the frame has sub-lights (FrameConfig::sub_lights, a probe's "sub_lights"):
// a constant, so that frames without them compile none of their loop.
layout(constant_id = MSM_SPEC_SUB_LIGHTS) const bool kSubLights = false;
// Whether some light of the frame is a spot light (FrameConfig::spot_lights): a constant, so that
// frames of directional lights compile none of the spot lights' projection and irradiance.
layout(constant_id = MSM_SPEC_SPOT_LIGHTS) const bool kSpotLights = false;
bool is_spot(int l) { return kSpotLights && lights[l].spot_position.w > 0.0f; }
// A point light's six entries (spot_cone.w: the face's number + 1): the light is evaluated once,
// at its first face's entry, from the face that holds the receiver; the other five only hold maps.
bool is_point(int l) { return is_spot(l) && lights[l].spot_cone.w > 0.5f; }
bool is_other_point_face(int l) { return is_spot(l) && lights[l].spot_cone.w > 1.5f; }
// Whether the directional lights have cascades (FrameConfig::cascades > 1): a constant, so that
// frames without them compile none of the cascades' weights.
layout(constant_id = MSM_SPEC_CASCADES) const bool kCascades = false;

layout(binding = MSM_BINDING_SHADING_ALBEDO_TEXTURE) uniform sampler2D albedo_texture;
layout(binding = MSM_BINDING_SHADING_OPACITY_TEXTURE) uniform sampler2D
    opacity_texture; // R8: used where object.flags.z != 0
layout(push_constant) uniform Push { ObjectPush object; };

#ifdef MSM_DEFERRED_SHADOWS
// Deferred shading (a full-screen pass): the visible surface of each pixel from the surfaces pass
// (MSM_SURFACES below), bit for bit what the forward pass interpolates, so one shadow evaluation per
// pixel gives the forward pass's result.
layout(binding = MSM_BINDING_SHADING_SURFACE_POSITION) uniform sampler2D
    surface_position; // xyz; w: 1 where a surface, 0 background
layout(binding = MSM_BINDING_SHADING_SURFACE_NORMAL) uniform sampler2D surface_normal; // xyz: towards the viewer
layout(binding = MSM_BINDING_SHADING_SURFACE_ALBEDO) uniform sampler2D surface_albedo; // rgb, a: opacity
layout(binding = MSM_BINDING_SHADING_SURFACE_GEOMETRIC_NORMAL) uniform sampler2D
    surface_geometric_normal; // xyz: the triangle's normal (triangle_normal)
vec3 world_position;
#else
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;

// The normal of the triangle the fragment lies on (either side), from the world position's screen
// derivatives: both lie in the triangle's plane, where the interpolation puts every position it
// extrapolates for the quad's other fragments. The interpolated normal of a faceted or coarse mesh
// turns across each triangle; the shadow pass rasterized the triangle itself. The fallback where the
// derivatives are within 0.06 degrees of parallel (a triangle seen edge-on), where their rounding
// would turn the cross product anywhere.
vec3 triangle_normal(vec3 fallback) {
  vec3 dx = dFdx(world_position), dy = dFdy(world_position);
  vec3 c = cross(dx, dy);
  float length2 = dot(c, c); // |dx|² |dy|² sin² of their angle
  return length2 > 1e-6f * dot(dx, dx) * dot(dy, dy) && !isinf(length2) ? c * inversesqrt(length2) : fallback;
}
#endif
// The receiver's geometric normal (triangle_normal; the deferred pass reads the surfaces pass's): the
// receiver plane of every light kind (light_visibility, spot_lookup) is the triangle's, as the depth
// pass drew it.
vec3 geometric_normal;

#ifdef MSM_SURFACES
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_albedo;
layout(location = 3) out vec4 out_geometric_normal;
#else
layout(location = 0) out vec4 out_color;  // tone mapped; the attachment is sRGB (kLinearRadiance: linear)
layout(location = 1) out vec4 out_shadow; // rgb: light visibility per colour channel, a: 1 (a surface)
#endif

#ifndef MSM_SURFACES

// Where a fragment looks up the shadow map: t in texel-centre coordinates (texel i covers
// [i - 0.5, i + 0.5)), z its depth in [0,1], and the receiver plane's depth per texel along x and
// y (from the surface normal: PCF and the plain map compare against the plane, not one depth).
struct ShadowLookup {
  vec2 t;
  float z;
  vec2 depth_per_texel;
  // Texels per pixel of t along screen x and y (the pixel's footprint on the surface, msm/footprint.h):
  // filtered lookups pick their mip from them. Not dFdx/dFdy: lavapipe's derivatives spike along the
  // edges of the slivers it clips large triangles into, and coarse mips show there as dark dashes.
  vec2 dt_dx, dt_dy;
};

float shadow_intensity(ShadowLookup s);
#ifdef MSM_COLOURED_SHADOWS
// Per colour channel (coloured translucency: the including shader defines it with the macro).
vec3 shadow_intensity_rgb(ShadowLookup s);
#endif

// The change of the map coordinate t (texels) along the world vector v at a point of clip
// coordinates clip in spot light l's perspective map.
vec2 spot_texels_along(int l, vec4 clip, vec3 v) {
  vec4 dv = lights[l].view_projection * vec4(v, 0.0f);
  return (vec2(dv) - vec2(clip) * (dv.w / clip.w)) * (0.5f * frame.shadow_map.x / clip.w);
}

// Spot light l's lookup of the receiver at world_position with normal n (docs/techniques.md, "Light
// kinds"): projected as the shadow pass projects the casters, its depth in the map's convention
// (radial distance / range) less the depth bias, which like the normal offset grows with the
// texel's world size (distance × texel angle): frame.shadow_map.w is the bias relative to the map's
// width where the receiver is. The receiver plane is the triangle's (geometric_normal): the
// interpolated normal's plane differs from it by the mesh's faceting, and at grazing light its
// slope by that angle over cos² of the incidence, which put the neighbouring texels of a lit facet
// in front of the plane (acne in bands on faceted columns at grazing light). Returns whether the
// receiver is inside the map's frustum.
bool spot_lookup(int l, vec3 n, float n_dot_l, MsmFootprint pixel, out ShadowLookup s) {
  vec3 light_position = lights[l].spot_position.xyz;
  float range = lights[l].spot_position.w;
  float width_per_distance = 2.0f * lights[l].spot_axis.w;
  vec3 p = world_position + n * (lights[l].spot_cone.z * distance(world_position, light_position) * (1.0f - n_dot_l));
  vec4 clip = lights[l].view_projection * vec4(p, 1.0f);
  vec2 ndc = vec2(clip) / clip.w;
  s.t = (ndc * 0.5f + 0.5f) * frame.shadow_map.x - 0.5f;
  s.dt_dx = spot_texels_along(l, clip, pixel.dp_dx);
  s.dt_dy = spot_texels_along(l, clip, pixel.dp_dy);
  float r = distance(p, light_position);
  s.z = msm_local_light_receiver_depth(r, range, frame.shadow_map.w, width_per_distance);
  // The receiver plane's radial depth per texel: d(r)/d(tangent) times d(tangent)/d(t).
  vec3 g = geometric_normal;
  vec3 tangent_x = normalize(abs(g.x) > 0.5f ? cross(g, vec3(0.0f, 1.0f, 0.0f)) : cross(g, vec3(1.0f, 0.0f, 0.0f)));
  vec3 tangent_y = cross(g, tangent_x);
  mat2 texels_per_tangent = mat2(spot_texels_along(l, clip, tangent_x), spot_texels_along(l, clip, tangent_y));
  vec3 away = (p - light_position) / max(r, 1e-20f);
  vec2 depth_per_tangent = vec2(dot(away, tangent_x), dot(away, tangent_y)) / range;
  float det = determinant(texels_per_tangent);
  float slope_limit = MSM_MAX_RECEIVER_DEPTH_SLOPE;
  s.depth_per_texel = abs(det) > 1e-12f
                          ? clamp(depth_per_tangent * inverse(texels_per_tangent), -slope_limit, slope_limit)
                          : vec2(0.0f);
  return clip.w > 0.0f && all(lessThanEqual(abs(ndc), vec2(1.0f))) && s.z <= 1.0f;
}

// Visibility of light l at the surface, per colour channel: 0 where none of its light reaches the
// surface (lit <= 0: its cosine factor, or with sub-lights their unshadowed irradiance's largest
// channel; the surface's own shadow).
vec3 light_visibility(int l, vec3 n, float n_dot_l, float lit, MsmFootprint pixel) {
  current_layer = l;
  ShadowLookup s;
  bool inside;
  if (is_spot(l)) {
    if (lit <= 0.0f) return vec3(0.0f);
    // A point light: the layer of the cube face the receiver's direction falls on, which its
    // guard band lets the lookup filter across the face's edges (msm/cube_face.h), at the mip
    // levels the guard band holds: coarser ones would read the blur's clamped edge.
    bool point = is_point(l);
    if (point) {
      l += msm_cube_face(world_position - lights[l].spot_position.xyz);
      current_layer = l;
    }
    inside = spot_lookup(l, n, n_dot_l, pixel, s);
    if (point) {
      float lod = log2(max(length(s.dt_dx), length(s.dt_dy)));
      float excess = lod - msm_cube_face_max_lod(s.t, frame.shadow_map.x, float(frame.kernel.z));
      if (excess > 0.0f) {
        s.dt_dx *= exp2(-excess);
        s.dt_dy *= exp2(-excess);
      }
    }
  } else {
    // Normal offset: more at grazing light, where depth varies fastest across a texel.
    vec3 p = world_position + n * (lights[l].towards_light.w * (1.0f - n_dot_l));
    vec4 clip = lights[l].view_projection * vec4(p, 1.0f);
    s.t = (clip.xy * 0.5f + 0.5f) * frame.shadow_map.x - 0.5f;
    float texels_per_clip_unit = 0.5f * frame.shadow_map.x;
    s.dt_dx = vec2(lights[l].view_projection * vec4(pixel.dp_dx, 0.0f)) * texels_per_clip_unit;
    s.dt_dy = vec2(lights[l].view_projection * vec4(pixel.dp_dy, 0.0f)) * texels_per_clip_unit;
    if (lit <= 0.0f) return vec3(0.0f);
    vec3 nc = mat3(lights[l].normal_matrix) * geometric_normal;
    s.z = clip.z - frame.shadow_map.w;
    // The receiver plane n_c . (dx, dy, dz) = 0 in clip space, of the triangle's normal n_c (as
    // spot_lookup's); one texel is 2 / size clip units.
    float slope_limit = MSM_MAX_RECEIVER_DEPTH_SLOPE; // per texel (frame.h)
    s.depth_per_texel = abs(nc.z) > 1e-6f
                            ? clamp(-vec2(nc.x, nc.y) / nc.z * (2.0f * frame.shadow_map.y), -slope_limit, slope_limit)
                            : vec2(0.0f);
    inside = all(greaterThanEqual(clip.xy, vec2(-1.0f))) && all(lessThanEqual(clip.xy, vec2(1.0f))) && clip.z <= 1.0f;
  }
#ifdef MSM_COLOURED_SHADOWS
  vec3 shadow = inside ? shadow_intensity_rgb(s) : vec3(0.0f);
#else
  vec3 shadow = vec3(inside ? shadow_intensity(s) : 0.0f);
#endif
  // Unconditional (the factor 1, no overdarkening, only clamps to [0, 1]): a branch on a uniform
  // makes lavapipe recompile the shader per frame, see kLightCount.
  shadow = vec3(msm_overdarken(shadow.x, frame.shading.x), msm_overdarken(shadow.y, frame.shading.x),
                msm_overdarken(shadow.z, frame.shading.x));
  return 1.0f - shadow;
}

// The unshadowed irradiance of light l's sub-lights (count of them, after their summary at entry
// rect_extent.z of lights[]; frame.h's SubLightsSummary): where the summary's
// rectangle about the light's direction, which holds them all, is above the horizon of n, their
// linear part (msm_linear_irradiance: one matrix product instead of a loop that reads each
// sub-light), where it is below, nothing; else each one's rectangle cosine integral.
vec3 sub_lights_irradiance(int l, vec3 n, int count) {
  int summary = int(lights[l].rect_extent.z);
  SubLightsSummary part = msm_sub_lights_summary(lights[summary].view_projection, lights[summary].normal_matrix);
  int side = msm_tangent_rect_side(n, lights[l].towards_light.xyz, part.x_axis, part.y_axis, part.bounds);
  if (side > 0) return max(msm_linear_irradiance(part.irradiance_by_direction, n), vec3(0.0f));
  if (side < 0) return vec3(0.0f);
  vec3 sum = vec3(0.0f);
  for (int k = summary + 1, end = k + count; k < end; ++k)
    sum += lights[k].irradiance.rgb * msm_light_cosine(n, lights[k].towards_light.xyz, lights[k].rect_x_axis.xyz,
                                                       lights[k].rect_extent.xy, lights[k].soft.z);
  return sum;
}

// Light l's direct light at the surface with normal n (towards the viewer), added to direct, and
// its visibility, returned and added to weighted with the irradiance it brings (luminance of
// E max(n·l, 0), for area lights msm_light_cosine: the same factor as the shading) as its weight.
vec3 add_direct_light(int l, vec3 n, MsmFootprint pixel, inout vec3 direct, inout vec3 weighted,
                      inout float weight_sum) {
  // A spot or point light: its direction and irradiance at the surface (msm_local_light_irradiance, the ray
  // tracer's formula); a directional light's are the same everywhere.
  if (is_other_point_face(l)) return vec3(0.0f); // lit from the point light's first face's entry
  vec3 towards_light = lights[l].towards_light.xyz;
  vec3 irradiance = lights[l].irradiance.rgb;
  float spot_sin_alpha = 0.0f; // a spot's sphere (soft.w: its radius) fills the cone of sin α = r / d
  if (is_spot(l)) {
    vec3 to_light = lights[l].spot_position.xyz - world_position;
    float d = length(to_light);
    towards_light = to_light / max(d, 1e-20f);
    spot_sin_alpha = min(lights[l].soft.w / max(d, 1e-20f), 1.0f);
    irradiance = msm_local_light_irradiance(irradiance, d, lights[l].spot_position.w,
                                            dot(-towards_light, lights[l].spot_axis.xyz), lights[l].spot_cone.x,
                                            lights[l].spot_cone.y);
  }
  // A cascade of a directional light brings its share at the surface's view depth (msm/cascade.h):
  // none outside its slice (no lookup there), part of it in the bands where it blends with the next.
  float cascade_weight = 1.0f;
  if (kCascades && !is_spot(l))
    cascade_weight =
        msm_cascade_weight(lights[l].cascade, (frame.camera_view_projection * vec4(world_position, 1.0f)).w);
  irradiance *= cascade_weight;
  float n_dot_l = dot(n, towards_light);
  // Area lights: the cosine integrated over the part of the light above the surface's horizon
  // (msm/light_probe.h; Eq. 15's π sin² α cos would go negative where the light dips below it):
  // the rectangle clipped by the horizon plane (msm_rect_light_cosine) or the disc's cone
  // (msm_cone_cosine); max(n·l, 0) for point lights (rect_extent = 0, soft.z = 0) and wherever
  // the whole light is above the horizon; 0 where it is all below. The other techniques shade
  // points (the renderer leaves soft.z and rect_extent 0): a branch on the specialization
  // constant, as llvmpipe runs both sides of a branch on a uniform under a mask, and the
  // rectangle's clipping would cost every pixel of every light.
  // Sub-lights (after the frame's lights in lights[], rect_extent.zw of their light): the light's
  // unshadowed irradiance is theirs (sub_lights_irradiance); the light's visibility shadows them all.
  int sub_count = kSubLights ? int(lights[l].rect_extent.w) : 0;
  vec3 unshadowed = vec3(0.0f);
  float lit;
  if (sub_count > 0) {
    unshadowed = sub_lights_irradiance(l, n, sub_count);
    lit = max(unshadowed.r, max(unshadowed.g, unshadowed.b));
  } else if (is_spot(l)) {
    // The cosine over the sphere's cone, as the ray tracer integrates it; a point (soft.w = 0, the
    // techniques of hard shadows): max(n·l, 0).
    lit = msm_cone_cosine(n_dot_l, asin(spot_sin_alpha));
  } else {
    lit = msm_technique_is_area_light(kTechnique)
              ? msm_light_cosine(n, lights[l].towards_light.xyz, lights[l].rect_x_axis.xyz, lights[l].rect_extent.xy,
                                 lights[l].soft.z)
              : msm_cone_cosine(n_dot_l, 0.0f);
  }
  // Where a spot light brings nothing (outside its cone, beyond its range) its visibility is 0, as
  // where a surface faces away from a light.
  if (is_spot(l) && max(irradiance.r, max(irradiance.g, irradiance.b)) <= 0.0f) lit = 0.0f;
  if (cascade_weight <= 0.0f) lit = 0.0f;
  vec3 v = light_visibility(l, n, n_dot_l, lit, pixel);
  float w;
  if (sub_count > 0) {
    direct += msm_direct_light(unshadowed, 1.0f, v);
    w = msm_luminance(unshadowed);
  } else {
    direct += msm_direct_light(irradiance, lit, v);
    w = msm_luminance(irradiance) * lit;
  }
  weighted += w * v;
  weight_sum += w;
  return v;
}

// Direct light of every light at world_position with normal n, and the shadow buffer's visibility
// of the direct light: with one light its visibility, with several their mean weighted by the
// irradiance each one brings.
void direct_light(vec3 n, out vec3 direct, out vec3 visibility) {
  vec3 weighted = vec3(0.0f);
  float weight_sum = 0.0f;
  direct = vec3(0.0f);
  MsmFootprint pixel = msm_surface_footprint(frame.camera_view_projection, frame.camera_viewport.xy, world_position, n);
  // One light: one pass through the body, no loop (light_loop.glsl).
  int l = 0;
  do {
    visibility = add_direct_light(l, n, pixel, direct, weighted, weight_sum);
  } while (!kOneLight && ++l < kLightCount);
  if (!kOneLight) visibility = weight_sum > 0.0f ? weighted / weight_sum : vec3(0.0f);
}

void write_shaded(vec4 albedo_opacity, vec3 direct, vec3 visibility) {
  vec3 radiance = msm_surface_radiance(albedo_opacity.rgb, direct, MSM_AMBIENT);
  // Alpha: the surface's opacity (translucent objects blend over the opaque image).
  float opacity = albedo_opacity.a;
  out_color = kLinearRadiance ? vec4(radiance, opacity) : vec4(msm_aces(radiance * frame.shading.y), opacity);
  out_shadow = vec4(visibility, 1.0f);
}
#endif // !MSM_SURFACES

#include "alpha_test.glsl"

#ifndef MSM_DEFERRED_SHADOWS
// The surface's albedo (rgb) and opacity (a).
vec4 surface_albedo_opacity() {
  vec3 albedo = object.albedo_opacity.rgb;
  if (kTexturedDraws && object.flags.x != 0) albedo *= texture(albedo_texture, texcoord).rgb;
  float opacity = object.albedo_opacity.a;
  if (kTexturedDraws && object.flags.z != 0) opacity *= texture(opacity_texture, texcoord).x;
  return vec4(albedo, opacity);
}
// The normal towards the viewer: only double-sided materials show back faces (culling).
vec3 facing_normal() { return gl_FrontFacing ? normalize(world_normal) : -normalize(world_normal); }
#endif

#if defined(MSM_SURFACES)
void main() {
  bool cut_out = !alpha_test_passes(object, kTexturedDraws, opacity_texture, texcoord);
  out_position = vec4(world_position, 1.0f);
  out_normal = vec4(facing_normal(), 0.0f);
  out_albedo = surface_albedo_opacity();
  out_geometric_normal = vec4(triangle_normal(out_normal.xyz), 0.0f);
  if (cut_out) discard;
}
#elif defined(MSM_DEFERRED_SHADOWS)
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 position = texelFetch(surface_position, p, 0);
  if (position.w == 0.0f) discard; // the background keeps its clear values
  world_position = position.xyz;
  geometric_normal = texelFetch(surface_geometric_normal, p, 0).xyz;
  vec3 direct, visibility;
  direct_light(texelFetch(surface_normal, p, 0).xyz, direct, visibility);
  write_shaded(texelFetch(surface_albedo, p, 0), direct, visibility);
}
#else
void main() {
  // Cut-outs (alpha mask) are discarded at the end: the lookups' derivatives need the whole quad.
  bool cut_out = !alpha_test_passes(object, kTexturedDraws, opacity_texture, texcoord);
  vec3 direct, visibility;
  vec3 n = facing_normal();
  geometric_normal = triangle_normal(n);
  direct_light(n, direct, visibility);
  write_shaded(surface_albedo_opacity(), direct, visibility);
  if (cut_out) discard;
}
#endif
