// msm::reference: ground truth for the renderer's shadows, by CPU ray tracing (Embree 3, TBB).
//
// render(scene, settings) traces one primary ray through the centre of every pixel and evaluates
// one Effect at the closest surface it hits. Everything is defined per pixel, exactly; Monte Carlo
// effects also report their sample count and standard error.
//
// Camera (identical to the rasterizer): an image of W x H pixels, pixel (x, y) with y = 0 the TOP
// row. The primary ray of pixel (x, y) goes through NDC ((x + 0.5) / W * 2 - 1, (y + 0.5) / H * 2 - 1)
// (Vulkan: y down, depth in [0, 1]): from the unprojection of NDC depth 0 to that of depth 1 with
// inverse(scene.camera_view_projection(float(W) / H)), in double precision. The closest hit over
// [near point, far point] that is opaque (not scene::Material::translucent(): no opacity below 1,
// no opacity texture or noise, no transmission colour) and not a back face of a single-sided
// material is the visible surface: translucent surfaces are looked through, as in the renderer's
// shadow buffer, and back faces (the triangle's winding turned away from the camera) of materials
// that are not double_sided are skipped, as the rasterizer culls them. Alpha-tested materials
// (scene::Material::alpha_cutoff) exist only where their opacity reaches the cutoff, for every
// ray (primary, shadow, transmission): their cut-outs are seen through and cast no shadow. The
// hit point p is the intersection of the (double precision) primary ray with the plane of the hit
// triangle; n is the triangle's geometric normal (not the interpolated one).
//
// Effects (L = scene.light.towards_light, the exact direction towards the light; every shadow
// ray starts at its point offset by eps along the geometric normal facing the light, with
// eps = kOffsetScale * max(|p|_inf, largest |coordinate| of the hit triangle's vertices); every
// surface blocks shadow rays, whatever its opacity, except in `translucent`):
//
//   hard        V(p) = 1 if the ray p -> L reaches infinity, else 0. One primary ray per pixel
//               centre, no bias beyond eps, no antialiasing: the renderer's shadow buffer.
//
//               With spot or point lights (scene.local_lights) the scene's every light is
//               shaded, each with its exact visibility V_l: a directional light's shadow ray runs
//               to infinity, a spot or point light's from p to the light's position (a light
//               inside a closed mesh lights nothing outside it), and E_l = the light's
//               LocalLight::irradiance_at(p) (I cone(θ) / d², 0 beyond its range). The radiance
//               is msm/shading.h's sum over the lights; "visibility" is their mean
//               Σ w_l V_l / Σ w_l weighted by w_l = luminance of E_l max(n·l_l, 0) (the
//               renderer's shadow buffer of several lights), 0 where no light arrives; n_dot_l
//               is the first light's (directional lights first). The soft effect does the same
//               with every light of some extent sampled over it (`samples` directions uniform in
//               the cone it fills, a spot or point light's sphere of `radius`: sin α = r / d, each
//               ray ending on the sphere; a directional light's disc of angular_extent_deg): each
//               light's lit = ∫ max(n·ω, 0) V dω / (π sin² α) replaces max(n·l, 0) V, visibility
//               = Σ lum(E_l) lit_l / Σ lum(E_l) lit0_l (lit0 unoccluded, the same samples). The
//               translucent effect: one ray per light, V_l the transmittance per channel of the
//               surfaces between p and the light (none beyond it), "visibility_rgb" the weighted
//               mean per channel and "visibility" their mean. The filtered effect: V_l the
//               light's filtered visibility (below), a spot's in its perspective map over the
//               outer cone, a point light's in the cube face that holds p's direction, the kernel
//               continuing on that face's plane across its seams (offsets o move the light ray's
//               tangents by o times the texel: 2 tan(outer) / shadow_size, 2 / shadow_size), the
//               ray meeting the receiver's tangent plane within MSM_MAX_RECEIVER_DEPTH_SLOPE x
//               range of radial distance per texel, its visibility a segment to the light; a
//               directional light's as for one light (at most one: the scene's light frame). The
//               environment effect, the light overrides and rectangular or probe lights with soft
//               refuse such scenes (std::invalid_argument).
//
//   filtered    What a filtered shadow map means, on any geometry (the renderer's PCF with
//               perfect depth): with n_s the interpolated normal turned towards the viewer (the
//               normal the renderer shades with), V(p) = 0 where n_s . L <= 0 (a surface turned
//               away from the light is in its own shadow, as the renderer has it; sample_count
//               0 there), else V(p) = integral of K(o) V_o do over the light's shadow-map plane,
//               K the continuous filter kernel of msm/reference/kernel.h (offsets o in texels)
//               and V_o the visibility of the light ray through the light-space (x, y) of p
//               moved by o, at the receiver's depth extrapolated along its plane: 1 unless a
//               surface lies between the light and q(o) = p + o_world + (s . o) D travel, where
//               o_world = ox * texel_x * x_axis + oy * texel_y * y_axis (LightFrame), D the map's
//               depth_range and s the receiver plane's depth per texel (the hit triangle's plane,
//               as the renderer's, whose interpolated normal n_s turns across a facet; each component
//               clamped to +-MSM_MAX_RECEIVER_DEPTH_SLOPE of msm/render/frame.h, as the renderer
//               clamps it), except surfaces within kOffsetScale * scale + kReceiverPlaneTolerance
//               * |o_world| of q(o) along the ray: those are the receiver's own surface, which the
//               plane models only to that tolerance (without it, a flat face whose interpolated
//               normal strays by 0.1 degree shadows itself: the "grey" of perfect-depth maps). Every
//               other surface counts, both faces, the receiver's own too (as in the map).
//               Estimated with `samples` stratified offsets, one ray each.
//
//   soft        Visibility averaged over a directional area light: the fraction of the light
//               that p sees. The light is a planar emitter at infinity: its directions are
//               normalize(L + a * x_axis + b * y_axis) with (a, b) uniform over a disc of radius
//               tan(extent / 2) (extent = angular DIAMETER) or over the rectangle
//               [-tan(w/2), tan(w/2)] x [-tan(h/2), tan(h/2)] (angular width w along light-space
//               x, height h along y; the axes are its shadow-map frame's, Scene::light_frame):
//               the scene light's own shape and extents (angular_extent_deg, angular_height_deg)
//               unless Settings overrides them (traced_light).
//               This is the light model of shadow-map soft shadows (penumbra width in light
//               space = 2 tan(extent/2) x distance to the blocker); it differs from a disc that
//               is uniform in solid angle by a density of cos^3 of the angle off L (relative
//               1.5 tan^2(extent/2): 1.1e-4 at 1 degree, 1.1e-2 at 10 degrees). Light arriving
//               from below the local horizon is blocked by the surface itself. Not weighted by the
//               cosine: visibility, not irradiance. Extent 0 gives the hard shadow.
//               The radiance replaces max(n·L, 0) V by the light's cosine-weighted visibility
//                 lit = ∫ max(n·d, 0) V(d) dω / ∫ (d·L) dω
//               over the light's directions, its radiance uniform in solid angle (the model of
//               msm_cone_cosine in msm/light_probe.h, which gives lit for V = 1 and the disc),
//               estimated as n·L + ∫ (max(n·d, 0) V − n·d) dω / ∫ (d·L) dω with the same samples,
//               each weighted by its solid angle (area / cos³ θ): exact where the whole light is
//               visible and above the horizon, sampled where it is not (light below the horizon
//               included: the test of the renderer's horizon-aware shading). Extent 0: max(n·L, 0) V.
//
//   translucent Coloured transmittance (JCGT 2017, Sec. 3), per RGB channel c:
//               T_c(p) = product over every surface i crossed by the ray p -> L of
//               (1 - channel_opacity(alpha_i)_c) = (1 - alpha_i * (1 - transmission_color_i,c)),
//               alpha_i the opacity of its material at the hit (the constant times the opacity
//               texture or procedural noise at the hit's uv, bilinear with repeat as the renderer
//               samples it), transmission_color_i its material's (scene::Material; default 0,
//               where every channel is the product of (1 - alpha_i)). The scalar visibility is
//               the mean (T_r + T_g + T_b) / 3, exactly T_r when the channels agree. A closed mesh
//               is crossed twice. At most max_crossings surfaces are counted.
//
//   scattering  Single scattering in the scene's homogeneous medium (scene.medium, required; JCGT
//               2017 §5.1.1, msm/scattering.h) along the view ray of every pixel, background too:
//               from the camera position c (not the near plane: scattering accumulates from the
//               eye, as the paper has it) along the primary ray's unit direction d to the visible
//               surface (s = |p - c|) or, where the ray hits nothing, to the far plane (s = |far
//               point - c|, what a depth buffer cleared to 1 gives). Every light l of the scene
//               scatters: its visible fraction
//                 V_l = integral_0^s exp(-st t) V_l(c + t d) dt / integral_0^s exp(-st t) dt
//               (V_l(q) = 1 if the ray q -> L_l reaches infinity, every surface blocking it) is
//               estimated with `samples` distances t drawn in proportion to st exp(-st t) on
//               [0, s] (inverse CDF; `stratified`: one per stratum of [0, 1)) and one shadow ray
//               per light from each, whose plain mean estimates V_l. The radiance is
//               msm/scattering.h's sum over the lights: exp(-st s) L_s + sum_l f_l E_l V_l
//               integral_0^s exp(-st t) dt, with f_l = msm_scattering_phase_term(st, albedo, g,
//               L_l, d) and L_s the surface's radiance lit by every light with its exact
//               (hard) shadow, 0 on background; "visibility" is V = sum_l w_l V_l / sum_l w_l
//               (w_l = msm_scattering_light_weight: the luminance of f_l E_l; one light: V_1),
//               its std_error that of the samples sum_l w_l V_l(t) / sum_l w_l. A camera inside an
//               occluder: the points inside are shadowed (their shadow rays hit its inside), its
//               back faces are looked through as above; nothing special, never NaN.
//               Spot and point lights scatter f E = msm_local_light_inscattering, which varies
//               along the ray (inverse square, the cone, the range): at the same distances t,
//               one shadow ray each to the light; V_l = sum lum(f E) V / sum lum(f E) and the
//               light's term V_l mean(f E) integral_0^s exp(-st t) dt; its weight w_l the
//               luminance of mean(f E). The surfaces are lit as by the hard effect.
//
//   environment Image-based lighting (Kneiphof 2017) with exact visibility: the irradiance
//                 E(p) = ∫ L(ω) V(ω) max(n_s·ω, 0) dω
//               (n_s the interpolated normal turned towards the viewer; directions below the
//               horizon of the geometric normal turned towards the viewer are blocked, V = 0),
//               L the scene's probe exactly as its median cut saw it (msm::probe::load_probe: the
//               same file, size, rotation and intensity; piecewise constant over the texels of the
//               cube's faces) plus the scene's directional lights that are not the probe's, as
//               uniform cones or rectangles (below). Each of the `samples` samples draws one direction from the
//               probe (a texel chosen in proportion to max(Y − Ȳ, 0) msm_cube_texel_weight, Y its luminance, Ȳ
//               the probe's mean, the choice stratified over all N samples; a uniform point of it on the face
//               plane: density p_texel / msm_cube_texel_weight there) and one from the cosine-weighted hemisphere
//               (Shirley-Chiu disc), balance heuristic: each adds f / (p_probe + p_cosine); p_probe = 0 below Ȳ.
//               --probe-lights (Settings::probe_lights): every light of the scene, the probe's
//               extracted area lights included, is a light of uniform radiance whose irradiance on
//               a facing surface is the light's `irradiance` (scene.cpp: Eq. 18 for the rectangle,
//               msm_rect_light_facing_fraction): a disc light a cone of half-angle alpha =
//               angular_extent_deg / 2 sampled uniformly in the cone, a rectangular one (the
//               probe's: Kneiphof §4.1.2) its rectangle on the axes of its shadow-map frame
//               (Scene::light_frame, as the renderer's spreads) sampled uniformly on its plane at
//               unit distance, weighted by cos³ θ (one direction per light per sample): the ground
//               truth of the area lights, whose difference from the probe's is the error of the
//               light extraction. The scene's other directional lights are drawn the same way.
//               The radiance is msm/shading.h's with this E: msm_surface_radiance(albedo,
//               msm_direct_light(E, 1, 1), MSM_AMBIENT). "visibility" = E_Y / E0_Y, the luminance of
//               E over that of the unoccluded E0 from the same samples (0 where E0_Y = 0);
//               std_error = that of E_Y (the sample values' luminance) over E0_Y. The irradiance
//               image holds E (R, G, B) and the standard error of its luminance.
//
// Samplers (filtered, soft, scattering, environment): `stratified` (default) uses a jittered m x m grid, m = floor(sqrt(N)),
// for the first m^2 of the N samples per pixel and independent uniform points for the rest (so a
// square N is fully stratified); the soft disc light maps the grid with Shirley and Chiu's
// concentric map, the filter kernel with FilterKernel::sample per axis. `independent` uses N
// independent uniform points (plain Monte Carlo, for checking the statistics). Every pixel draws
// from its own generator seeded by (seed, x, y, effect): the image is the same for any thread
// count. std_error = s / sqrt(N) with s^2 the unbiased sample variance: the standard error of the
// mean of N independent samples; for the stratified sampler the actual error is smaller (the
// variance of a stratified mean never exceeds that of independent sampling), so it is an upper
// bound there. It is 0 where N = 1 or every sample agrees.
//
// Output images (W x H, row 0 at the top):
//   visibility   channels "visibility", "background" and, for filtered and soft only,
//                "sample_count", "std_error". background = 1 where the primary ray hits nothing
//                (there visibility = 1, sample_count = std_error = 0), else 0. For translucent,
//                "visibility" is the mean of the three channel transmittances.
//   visibility_rgb  translucent only (empty for the other effects; an image holds at most 4
//                channels, so not in `visibility`): "visibility_r", "visibility_g",
//                "visibility_b" = T_r, T_g, T_b; 1 on background.
//                scattering: "visibility" is the visible fraction V of the view ray (on background
//                pixels too), with "sample_count" and "std_error".
//   scattering   scattering only: "R", "G", "B" the in-scattered radiance sum_l f_l E_l V_l
//                integral_0^s exp(-st t) dt alone, "length" the ray's length s.
//   radiance     "R", "G", "B" (linear): msm/shading.h's radiance at the visible surface; on background
//                the radiance of a probe-lit scene's probe in the ray's direction (its texel
//                msm_cube_texel of msm::probe::load_probe's cube, as the renderer shows it), else 0;
//                scattering: that radiance attenuated plus the in-scattered (msm_scattered_radiance);
//                for translucent with the visibility of each channel (T_r, T_g, T_b) in its
//                channel. Result::mean_visibility averages "visibility".
//   surface      "n_dot_l": the cosine of the radiance (msm/shading.h) (interpolated normal turned towards the viewer,
//                dotted with L; 0 on background), "object": the index into scene.objects of the
//                visible surface (-1 on background; a mesh with several materials is several
//                objects). Masks for comparisons: the terminator (n_dot_l near 0), where shadow
//                maps and ray tracing disagree by design, or one object.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string_view>

#include <glm/glm.hpp>

#include "msm/image/image.h"
#include "msm/reference/kernel.h"
#include "msm/scene/scene.h"

namespace msm::reference {

enum class Effect { hard, filtered, soft, translucent, scattering, environment };
inline constexpr std::array<Effect, 6> kEffects{Effect::hard,        Effect::filtered,   Effect::soft,
                                                Effect::translucent, Effect::scattering, Effect::environment};
std::string_view to_string(Effect effect);
std::optional<Effect> parse_effect(std::string_view name);
bool is_monte_carlo(Effect effect); // filtered, soft, scattering, environment

enum class LightShape { disc, rectangle };
std::string_view to_string(LightShape shape);
std::optional<LightShape> parse_light_shape(std::string_view name);

enum class Sampler { stratified, independent };
std::string_view to_string(Sampler sampler);
std::optional<Sampler> parse_sampler(std::string_view name);

inline constexpr int kMaxSide = 16384;
inline constexpr int kMaxSamples = 1'000'000;
inline constexpr int kMaxShadowSize = 65536;
inline constexpr int kMaxCrossings = 4096;
inline constexpr int kMaxThreads = 1024;
inline constexpr double kOffsetScale = 1e-5; // shadow-ray origin offset, relative
// filtered: surfaces within this times |o_world| of the receiver plane are the receiver itself
// (the plane's slope is known to about 0.3 degrees: real meshes' interpolated normals stray from
// their flat faces by this much, 0.11 degrees on the 2CylinderEngine's covers).
inline constexpr double kReceiverPlaneTolerance = 0.005;

// The shadow map's light-space frame (x_axis, y_axis, extent: one texel is extent / shadow_size
// along each axis; depth_extent the world distance from depth 0 to 1), shared with the renderer:
// msm::scene::LightFrame of the scene's first light.
using scene::LightFrame;

struct Progress {
  std::size_t rows_done = 0, rows_total = 0;
  double seconds = 0.0; // since the start of the render (BVH build included)
};

struct Settings {
  Effect effect = Effect::hard;
  int width = 640, height = 360; // 1..kMaxSide
  int samples = 256;             // per pixel (filtered, soft, scattering), 1..kMaxSamples
  std::uint64_t seed = 1;
  Sampler sampler = Sampler::stratified;
  // filtered: the renderer's shadow map and filter.
  int shadow_size = 1024;                         // 1..kMaxShadowSize
  int filter_size = MSM_FILTER_DEFAULT_TAPS;      // odd, 1..MSM_FILTER_MAX_TAPS (msm/filter.h)
  double filter_sigma = MSM_FILTER_DEFAULT_SIGMA; // texels
  // soft: overrides of the scene's light, each in [0, 90) degrees; none set: the light exactly as
  // the scene declares it (a disc, or a rectangle where it has angular_height_deg). The light is
  // scene::overridden_light(light, light_extent_deg, light_height_deg), as the renderer draws it;
  // then light_shape, where set, makes it that shape, and light_width_deg (a rectangle's only)
  // replaces its width. A rectangle's height without an override or a height of its own: its
  // extent.
  std::optional<double> light_extent_deg;
  std::optional<LightShape> light_shape;
  std::optional<double> light_width_deg, light_height_deg; // a rectangle's
  // translucent
  int max_crossings = 64; // 1..kMaxCrossings
  // environment: lit by the scene's extracted area lights (every light a uniform cone) instead of
  // the full probe: the "lights" half of the error split.
  bool probe_lights = false;
  // Worker threads: 0 = TBB's default (all cores, or a tbb::global_control limit), else a
  // task arena of that many (1..kMaxThreads). The image does not depend on it.
  int threads = 0;
  // Called from worker threads (one at a time) as rows complete, at most ~200 times.
  std::function<void(const Progress&)> progress;
};

// Throws std::invalid_argument naming the setting and its allowed range (or a width or height
// given to a disc).
void validate(const Settings& settings);

// The soft light that render() traces for `light` under the settings' overrides (Settings):
// its shape and angular extents in degrees (a disc's width and height its diameter).
struct TracedLight {
  LightShape shape = LightShape::disc;
  double extent_deg = 0.0, width_deg = 0.0, height_deg = 0.0;
};
TracedLight traced_light(const scene::DirectionalLight& light, const Settings& settings);
// What render() would allocate for a scene of `triangles` triangles: the tracer's BVH and the
// per-pixel images (the model and its constants: msm/util/limits.h).
std::uint64_t estimated_bytes(const Settings& settings, std::uint64_t triangles);
// limits::LimitError when the scene or the estimate exceeds its limit (the same limits as the
// renderer's); render() checks it first.
void check_limits(const Settings& settings, std::uint64_t triangles);

struct Result {
  image::Image visibility;     // see above for the channels
  image::Image visibility_rgb; // translucent: T_r, T_g, T_b ("visibility_r/_g/_b"); else empty
  image::Image scattering;     // scattering: R, G, B in-scattered radiance, length; else empty
  image::Image radiance;       // R, G, B
  image::Image irradiance;     // environment: R, G, B irradiance E, "std_error" of its luminance; else empty
  image::Image surface;        // n_dot_l, object (see above)
  int samples = 1;             // per covered pixel (1 for hard and translucent)
  LightShape light_shape = LightShape::disc;                                    // as traced (soft)
  double light_extent_deg = 0.0, light_width_deg = 0.0, light_height_deg = 0.0; // as traced (soft)
  double build_seconds = 0.0;                                                   // Embree scene
  double render_seconds = 0.0;                                                  // tracing
  std::uint64_t rays = 0;                                                       // primary + shadow rays traced
  std::size_t background_pixels = 0;
  bool probe_background = false; // the background's radiance is the scene's probe (see radiance)
  double mean_visibility = 0.0;  // over the covered (non-background) pixels; 1 if none; scattering: the
                                 // mean visible fraction over every pixel
  unsigned threads = 0;          // TBB concurrency used
};

// Throws std::invalid_argument for bad settings, a scene with non-finite vertices or, for
// scattering, a scene without a medium, for environment, a scene without a probe, and
// std::runtime_error when Embree fails.
Result render(const scene::Scene& scene, const Settings& settings);

} // namespace msm::reference
