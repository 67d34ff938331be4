// msm::scene: the scene description shared by the Vulkan renderer and the CPU ray tracer.
//
// A scene is a JSON file (schema below, examples in scenes/*.json, same text in scenes/README.md).
// Loading it yields world-space triangle soups, materials, a camera, one directional light and the
// shadow-map framing. The built-in scenes reproduce the papers' stress cases; builtin_scene(name)
// is exactly what loading scenes/<name>.json gives (the files are embedded at build time).
//
// Conventions: right-handed, +Y up, lengths in scene units (metres in the built-ins).
//
// ---------------------------------------------------------------------------------------------
// JSON schema (every key optional unless marked REQUIRED; unknown keys are errors, so typos are
// reported; comments /* */ and // are accepted):
//
// {
//   "msm_scene": 1,                        REQUIRED format version (only 1 exists)
//   "name": "fence",                       informative
//   "camera": {
//     "position": [x,y,z], "target": [x,y,z], "up": [0,1,0],
//     "fov_y_deg": 45,                     vertical field of view, in (0, 180)
//     "near": 0.1, "far": 1000             1e-6 <= near < far <= 1e9, far / near <= 1e7
//   },
//   "probe": {                             image-based lighting (Kneiphof 2017): a light probe split
//                                          by the median cut into area lights, added after "light" /
//                                          "lights" (which become optional); msm::probe
//     "file": "studio.exr" | "sky",        REQUIRED equirectangular EXR or cube-map cross (relative to
//                                          the scene file), six face EXRs named by a path with
//                                          "{face}" (px nx py ny pz nz: msm::probe::cube_face_files;
//                                          a cross and faces cannot be rotated), or the procedural
//                                          sky with a sun ("msm probe sky")
//     "lights": 32,                        area lights, 1..256 (all lights together <= kMaxLights)
//     "intensity": 1,                      radiance scale, [0, 1e6]
//     "rotation_deg": 0,                   about +Y, counter-clockwise seen from above
//     "size": 128                          cube-map face size, 1..1024
//   },
//   "light": {                             ONE directional light
//     "towards_light": [x,y,z],            REQUIRED direction FROM the scene TOWARDS the light
//                                          (normalized on load; the light travels along -this)
//     "irradiance": [r,g,b],               >= 0, default [3,3,3]
//     "angular_extent_deg": 0              angular diameter of the light, [0, 90); 0 = hard
//     "angular_height_deg": h              optional: the light is a rectangle (Kneiphof §4.1.2) of
//                                          angular width angular_extent_deg along x_axis and height h,
//                                          [0, 90), along the third axis; without it, a disc whose
//                                          shadow kernel is the square box covering it
//     "x_axis": [x,y,z]                    optional: the direction of the width, projected orthogonal
//                                          to towards_light (not parallel to it); default: the light
//                                          frame's horizontal axis (Scene::light_view)
//   },
//   "lights": [ <light>, ... ]             instead of "light": 1..kMaxLights lights of any kinds
//                                          (LightKindInfo, glTF KHR_lights_punctual's vocabulary):
//     {"type": "directional", ...}         "type" optional (the default); the keys of "light"
//     {"type": "spot",
//      "position": [x,y,z],                REQUIRED
//      "direction": [x,y,z],               REQUIRED where the light shines (normalized on load)
//      "inner_cone_deg": 0,                half-angles: 0 <= inner <= outer, outer in (0, 90); full
//      "outer_cone_deg": 45,               intensity within inner, glTF's smooth falloff to 0 at outer
//      "range": r,                         > 0 metres, the light ends there (default: unbounded)
//      "intensity": [1,1,1],               radiant intensity W/sr, >= 0; irradiance I / d² (LocalLight)
//      "radius": 0}                        >= 0 metres, the emitter's size for soft shadows (0: a point)
//     {"type": "point", "position", "range", "intensity", "radius"}   as for "spot"; every direction
//                                          A light inside a closed mesh lights nothing outside it.
//   "shadow_map": {
//     "framing": "fit"                     default: orthographic light frustum fitted to what the
//                                          camera sees (fit_light_frustum)
//     | "framing": "fit_scene"             fitted to every vertex of the scene
//     | "framing": "explicit",
//       "center": [x,y,z],                 world-space centre of the light frustum
//       "extent": [w,h],                   full width/height across the light direction, > 0
//       "depth_range": [n,f]               signed distances from center along the direction of
//                                          travel (-towards_light), n < f; depth 0 at n, 1 at f
//   },
//   "medium": {                            a homogeneous participating medium filling the scene, lit
//                                          by the light(s): single scattering (include/msm/scattering.h)
//     "extinction": 0.1,                   REQUIRED σt in 1/scene units, in (0, 1e6]
//     "scattering_albedo": 1,              ρ in [0, 1]: scattering coefficient σs = ρ σt
//     "phase": "isotropic"                 default
//     | "phase": "henyey_greenstein", "g": 0.5   asymmetry g in (-1, 1) (> 0 scatters forwards)
//   },
//   "materials": { "name": <material>, ... },   named materials that objects may refer to
//   "objects": [ <object>, ... ]           REQUIRED, at least one
// }
//
// <material> = {
//   "albedo": [r,g,b] in [0,1] (default [0.8,0.8,0.8]), "albedo_texture": "path.png",
//   "opacity": 1 in [0,1], "opacity_texture": "alpha.png" (alpha channel, or the grey value),
//   "opacity_noise": {"seed": 1, "scale": 4, "octaves": 4, "density": 0.5, "softness": 0.25}
//                                          procedural puff of smoke instead of a texture file
//                                          (see make_smoke_opacity); at most one of the two,
//   (a constant given together with a texture multiplies it)
//   "transmission_color": [r,g,b] in [0,1] (default [0,0,0]): of the light meeting the covered
//                                          fraction (opacity alpha) the fraction that passes, per
//                                          channel; per-channel opacity alpha*(1 - transmission_color)
//                                          (coloured shadows; see Material::channel_opacity)
//   "alpha_cutoff": c in [0,1]             alpha testing (glTF alphaMode MASK): present where the
//                                          opacity reaches c, a cut-out elsewhere (Material::alpha_cutoff)
//   "double_sided": false
// }
// Texture paths are relative to the scene file; they must exist when the scene is loaded but are
// only read by load_texture().
//
// <object> = {
//   "name": "wall",                        default "object<i>"; used in error messages
//   "mesh": "models/bunny.obj"             file relative to the scene file (glTF 2.0 .gltf/.glb,
//                                          OBJ, PLY, OFF and whatever else Assimp reads); node
//                                          transforms are applied, normals generated if missing;
//                                          without "material", one object "<name>/<material>" per
//                                          material of the file (import_model; scenes/README.md)
//   | "primitive": { "type": ..., parameters },  exactly one of "mesh" / "primitive"
//   "transform": {
//     "translate": [x,y,z],
//     "rotate": [rx,ry,rz]                 Euler angles in degrees, applied X first, then Y, then Z
//             | {"axis": [x,y,z], "angle_deg": a},
//     "scale": s | [sx,sy,sz]              > 0 (no mirroring)
//   },                                     world = translate * rotate * scale * local
//   "material": <material> | "name"        default: the default material
//   "import_lights": false                 a glTF "mesh" (.gltf, .glb): its KHR_lights_punctual lights
//                                          join the scene's, placed by the file's nodes (the light
//                                          shines along its node's -Z) and then "transform" (a range
//                                          scaled by the largest scale); colour × intensity taken as
//                                          W/sr (spot, point) or irradiance (directional); checked as
//                                          "lights" (an outer cone of 90°, which glTF allows, is
//                                          refused). With it the scene needs no "light" of its own.
//                                          Not with "motion".
//   "motion": {                            an animated object (`msm render --frames`, `msm reference
//                                          --frame`; at_frame): per frame, a turn about an axis
//                                          through the object's origin (its "translate"), then a move
//     "translate": [x,y,z],                scene units per frame (default [0,0,0]; |component| <= 1e3:
//                                          kMaxMotionPerFrame)
//     "rotate": {"axis": [x,y,z], "angle_deg": a}   degrees per frame, |a| <= 360 (default none)
//   }
// }
//
// Primitives (local frames; sizes > 0 and <= 1e6; segment counts capped, see kMax* below):
//   plane       {"size": [w,d], "subdivisions": [nx,nz]=[1,1]}   in y = 0, normal +Y, centred
//   box         {"size": [x,y,z]}                                centred, 6 faces x 2 triangles
//   sphere      {"radius": r, "segments": 64, "rings": 32}       centred (UV sphere)
//   cylinder    {"radius": r, "height": h, "segments": 64, "caps": true}  axis Y, centred
//   fence       {"length": 4, "height": 1, "bars": 9, "bar_width": 0.05, "bar_depth": 0.05,
//                "rails": 2, "rail_height": 0.05}                vertical bars along X, rails at
//                                          the top (and evenly below); stands on y = 0, centred
//                                          in x and z. A railing is a fence with thin bars.
//   stair       {"steps": 5, "width": 2, "step_depth": 0.3, "step_height": 0.2}
//                                          solid steps rising towards -Z; stands on y = 0, the
//                                          first step's front face at z = 0, centred in x
//   torus_knot  {"p": 2, "q": 3, "radius": 1, "tube_radius": 0.15, "segments": 256,
//                "tube_segments": 16}      procedural "model" (centred)
//   brick_wall  {"rows": 12, "columns": 8, "brick_length": 0.24, "brick_height": 0.07,
//                "mortar": 0.012, "relief": 0.02, "thickness": 0.2}
//                                          a mortar core (x centred, on y = 0, front face z = 0,
//                                          back face z = -thickness) with bricks in running bond
//                                          protruding from its front by relief (odd rows shifted
//                                          by half a brick, cut at the ends); mortar joints and
//                                          borders `mortar` wide; mortar < brick_length, brick_height
//
// Errors: every problem throws SceneError naming the file, the JSON pointer (and the object's
// name) and what is wrong: malformed JSON, unknown keys/primitive/scene names, missing or
// unreadable meshes/textures, NaN/infinite positions, meshes with only degenerate triangles,
// scale <= 0, fov outside (0,180), absurd camera near/far, opacity, albedo, alpha_cutoff or
// transmission_color outside [0,1], absurd sizes or segment counts.
// Degenerate (zero-area) triangles in otherwise valid meshes are dropped silently.
//
// Clip-space conventions (camera and light matrices): Vulkan: x right, y DOWN in NDC (an image
// rendered with these matrices is upright with row 0 at the top), depth z in [0,1] (0 = near),
// right-handed view space looking down -Z. Not reversed-Z.
// ---------------------------------------------------------------------------------------------
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace msm {
struct MsmAreaLight; // msm/light_probe.h
namespace probe {
struct ProbeLight; // msm/probe/probe.h
}
} // namespace msm

namespace msm::scene {

// Caps against absurd input (checked before anything is allocated).
inline constexpr int kMaxSegments = 4096; // any one segment/ring/step/bar count
inline constexpr std::size_t kMaxPrimitiveTriangles = 4'000'000;
inline constexpr float kMaxSize = 1e6f; // any primitive dimension / |translate|
// |component| of a motion's translation per frame: with `msm render`'s 10000 frames at most,
// objects stay within kMaxSize × 10 of the scene.
inline constexpr float kMaxMotionPerFrame = 1e3f;
inline constexpr int kMaxLights = 256; // render/frame.h MSM_MAX_LIGHTS: the layers of a shadow-map array
// Camera depth range: near in [kMinCameraNear, kMaxSize], far <= kMaxCameraFar and far / near <=
// kMaxCameraDepthRatio (beyond, the float depth buffer cannot tell surfaces apart).
inline constexpr float kMinCameraNear = 1e-6f;
inline constexpr float kMaxCameraFar = 1e9f;
inline constexpr double kMaxCameraDepthRatio = 1e7;

class SceneError : public std::runtime_error {
 public:
  // what() = "<file>: <where>: <problem>" (file or where omitted when empty).
  SceneError(std::string file, std::string where, std::string problem);
  const std::string& file() const noexcept { return file_; }
  const std::string& where() const noexcept { return where_; } // JSON pointer (+ object name)
  const std::string& problem() const noexcept { return problem_; }

 private:
  std::string file_, where_, problem_;
};

struct Bounds {
  glm::vec3 min{1e30f};
  glm::vec3 max{-1e30f};
  bool empty() const { return min.x > max.x; }
  void extend(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Bounds& b) {
    if (!b.empty()) {
      extend(b.min);
      extend(b.max);
    }
  }
  glm::vec3 center() const { return 0.5f * (min + max); }
  glm::vec3 size() const { return max - min; }
};

// Indexed triangle soup; normals are unit length, uvs zero where the source has none.
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices; // 3 per triangle, counter-clockwise seen from the front
  std::size_t triangle_count() const { return indices.size() / 3; }
  double area() const; // sum of triangle areas
  Bounds bounds() const;
};

// A procedural opacity texture: a round puff of smoke (fractal value noise under a soft disc).
struct SmokeNoise {
  std::uint32_t seed = 1;
  float scale = 4.0f;     // noise cells across the texture, (0, 64]
  int octaves = 4;        // 1..8
  float density = 0.5f;   // noise level at which the opacity is one half, [0, 1]
  float softness = 0.25f; // width of the noise-to-opacity ramp, (0, 1]
};

// Decoded texels, always 4 channels RGBA8, row 0 = the top row of the picture (texture coordinate
// v = 0).
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
};

// Texture coordinates everywhere (primitives, imported meshes, renderer, ray tracer): (0, 0) is
// the top-left corner of the picture, u to the right, v DOWN (glTF's, Vulkan's and Direct3D's
// convention); formats with v up (OBJ and most others) are flipped on import.
struct Material {
  std::string name; // key in "materials", or empty for inline ones
  glm::vec3 albedo{0.8f};
  // A file (absolute or relative to the CWD), or for a picture embedded in a mesh file (GLB, data
  // URI) "<mesh file>#<index>" with the texels in albedo_pixels; empty = none.
  std::filesystem::path albedo_texture;
  std::shared_ptr<const Image> albedo_pixels;
  float opacity = 1.0f;
  std::filesystem::path opacity_texture; // as albedo_texture, embedded ones in opacity_pixels
  std::shared_ptr<const Image> opacity_pixels;
  // The opacity texture's alpha channel even where it is 255 everywhere (glTF: the base colour's
  // alpha); otherwise the alpha channel, or the red one where alpha is all 255 (grey masks).
  bool opacity_from_alpha = false;
  std::optional<SmokeNoise> opacity_noise; // procedural opacity (instead of opacity_texture)
  // Alpha testing (glTF alphaMode MASK): where the opacity (constant times texture) is below the
  // cutoff the surface is absent (a cut-out: no shadow, seen through), elsewhere it is opaque.
  // Such a material is not translucent, whatever its opacity.
  std::optional<float> alpha_cutoff;
  bool double_sided = false;
  // Coloured transmission (JCGT 2017, Sec. 3): of the light that meets the covered fraction (the
  // opacity alpha) of this surface, the fraction that passes, per RGB channel, each in [0, 1].
  // Default 0: the covered fraction blocks all channels alike (grey shadows, as without it).
  glm::vec3 transmission_color{0.0f};
  // Per-channel opacity at a point of opacity alpha (the constant times texture/noise there):
  // alpha * (1 - transmission_color). Equals vec3(alpha) for the default transmission colour.
  glm::vec3 channel_opacity(float alpha) const { return alpha * (glm::vec3(1.0f) - transmission_color); }
  bool masked() const { return alpha_cutoff.has_value(); }
  // Lets light through somewhere: an opacity constant below 1, an opacity texture, procedural
  // noise, or any transmission_color component > 0 (stained glass of opacity 1 still transmits);
  // never an alpha-tested (masked) material.
  bool translucent() const {
    return !masked() && (opacity < 1.0f || !opacity_texture.empty() || opacity_noise.has_value() ||
                         glm::any(glm::greaterThan(transmission_color, glm::vec3(0.0f))));
  }
};

struct Transform {
  glm::vec3 translate{0.0f};
  glm::mat3 rotate{1.0f};
  glm::vec3 scale{1.0f};
  glm::mat4 matrix() const; // translate * rotate * scale
};

// An object's motion over a frame sequence, per frame: a turn of angle_deg about `axis` through
// the object's origin (its transform's translate), then a move by `translate` (at_frame).
struct Motion {
  glm::vec3 translate{0.0f};
  glm::vec3 axis{0.0f, 1.0f, 0.0f}; // unit
  float angle_deg = 0.0f;
};

struct Object {
  std::string name;
  std::filesystem::path mesh_file; // empty for primitives
  std::string primitive;           // primitive type, empty for meshes
  Transform transform;
  std::optional<Motion> motion; // the JSON's "motion": an animated object
  std::uint32_t material = 0;   // index into Scene::materials
  Mesh mesh;                    // world space
  Bounds bounds;                // world space
};

struct Camera {
  glm::vec3 position{0.0f, 2.0f, 6.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y_deg = 45.0f;
  float near = 0.1f;
  float far = 1000.0f;
  glm::mat4 view() const;
  glm::mat4 projection(float aspect) const; // Vulkan clip conventions (see above)
};

struct DirectionalLight {
  glm::vec3 towards_light{0.0f, 1.0f, 0.0f}; // unit, from the scene towards the light
  glm::vec3 irradiance{3.0f};                // on a surface facing the light
  // The light's angular size, both in [0, 90). Without angular_height_deg: a disc of angular
  // diameter angular_extent_deg (its soft-shadow kernel the square box covering it: both spreads
  // equal). With it: a rectangle of angular width angular_extent_deg along the light frame's x axis
  // and height angular_height_deg along its y axis (the probe's area lights, Kneiphof §4.1.2).
  float angular_extent_deg = 0.0f; // 0 = hard shadows
  std::optional<float> angular_height_deg;
  // The direction of the width (the light frame's x axis once projected orthogonal to
  // towards_light); unset: the frame's default, horizontal (Scene::light_view). The probe's lights:
  // the u axis of their cube face (§4.1.2).
  std::optional<glm::vec3> x_axis;
  // A probe light's sub-lights (ProbeLighting::sub_lights): the lights of a finer median cut inside
  // its region, each a rectangle with its own direction, extents and irradiance. Where given, the
  // shading takes the light's unshadowed irradiance as their sum (each clipped by the receiver's
  // horizon) instead of this light's own; its shadow map and visibility stay this light's.
  std::vector<DirectionalLight> sub_lights;
  glm::vec3 travel() const { return -towards_light; }
  bool rectangular() const { return angular_height_deg.has_value(); }
  // tan of the half extents along the frame's x and y axes (a disc: its radius, both).
  glm::vec2 tan_half_extents() const;
  // The half-angle in radians of the cone of a disc (msm_cone_cosine shades it) or of a rectangle's
  // solid angle (msm_rect_light_cone_half_angle; the rectangle itself is shaded as one).
  float cone_half_angle() const;
  // What the shading takes for msm_light_cosine (msm/light_probe.h): a rectangle's
  // tan_half_extents(), 0 for a disc or a point (shaded by the cone of cone_half_angle()).
  glm::vec2 rectangle_extents() const { return rectangular() ? tan_half_extents() : glm::vec2(0.0f); }
};

// ---- Light kinds ------------------------------------------------------------------------------
//
// The kinds of light a scene declares (each entry of "lights" names one by its "type", glTF
// KHR_lights_punctual's vocabulary). LightKindInfo is their one declaration: the loader reads its
// keys, the renderer whether it draws the kind, the ray tracer how it samples it, the docs
// (docs/techniques.md, "Light kinds") its projection and depth convention.
enum class LightKind { directional, spot, point };

struct LightKindInfo {
  LightKind kind = LightKind::directional;
  std::string_view name;                  // the scene's "type"
  std::span<const std::string_view> keys; // its JSON keys besides "type"
  std::string_view projection;            // of its shadow map
  int shadow_views = 1;                   // shadow-map views per light (a point light's cube: 6)
  std::string_view depth;                 // what its shadow map stores
  std::string_view traced;                // how the ray tracer (msm reference) samples it
  bool rendered = false;                  // the renderer (msm render, msm view) draws its shadows
};
std::span<const LightKindInfo> light_kinds();
const LightKindInfo& light_kind(LightKind kind);
std::optional<LightKind> parse_light_kind(std::string_view name);

// A spot or point light (glTF KHR_lights_punctual): a point source of radiant intensity
// `intensity` (W/sr) at `position`, whose irradiance on a surface facing it at distance d is
// intensity / d² (msm/local_light.h), none beyond `range`; a spot light's times glTF's smooth cone
// falloff about `direction` between inner_cone_deg and outer_cone_deg.
struct LocalLight {
  LightKind kind = LightKind::point; // spot or point
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f}; // spot: unit, where the light shines
  // Spot: half-angles from `direction`, 0 <= inner <= outer < 90 (a perspective shadow map's field
  // of view is below 180°); full intensity within inner, none beyond outer.
  float inner_cone_deg = 0.0f, outer_cone_deg = 45.0f;
  float range = kInfiniteRange; // metres, > 0: the light ends there (glTF: infinite when absent)
  glm::vec3 intensity{1.0f};    // W/sr, >= 0
  float radius = 0.0f;          // the emitter's radius for soft shadows, >= 0 (0: a hard point)

  static constexpr float kInfiniteRange = 3.0e38f;
  bool spot() const { return kind == LightKind::spot; }
  // Cosines of the cone's half-angles (a point light: -1, -1, every direction in full).
  float cos_outer() const;
  float cos_inner() const;
  // The irradiance on a surface at p facing the light (msm_local_light_irradiance): intensity / d²
  // times the cone's falloff, 0 beyond range; and the unit direction from p towards the light.
  glm::vec3 irradiance_at(const glm::vec3& p) const;
};

// One entry of a scene's "lights" (its JSON text, "type" and the kind's keys), checked by the
// scene loader's own rules, ranges and messages: the light it declares. SceneError "<source>:
// <where>/<key>: problem". What a tool that edits lights (msm view) checks an edit with.
struct DeclaredLight {
  LightKind kind = LightKind::directional;
  DirectionalLight directional; // kind directional
  LocalLight local;             // spot, point
};
DeclaredLight parse_light(std::string_view json_text, const std::string& source, const std::string& where);

// The light that the renderer, the ray tracer and the viewer draw for `light` under a command
// line's (or a viewer's) overrides, the one rule for all three: an extent alone replaces the light
// by a disc of that angular diameter; a height makes it a rectangle of that height, its width the
// extent (given, else its own). Neither: the light exactly as the scene declares it, a rectangle
// where it has angular_height_deg.
DirectionalLight overridden_light(DirectionalLight light, std::optional<float> extent_deg,
                                  std::optional<float> height_deg);

// A homogeneous medium (JCGT 2017 §5.1.1): extinction σt, scattering albedo ρ and a Henyey–
// Greenstein phase function of asymmetry g (g = 0: isotropic). Lit by the scene's light(s) with
// their irradiance E_l.
struct Medium {
  float extinction = 0.1f;        // σt > 0, per scene unit
  float scattering_albedo = 1.0f; // ρ in [0, 1]
  float g = 0.0f;                 // in (-1, 1)
};

// The rectangular light that the renderer and the ray tracer draw for an area light of a probe:
// its direction, its face's u axis, its angular width and height (each kept below 90°, their limit
// on the extents) and the irradiance a facing surface receives (Eq. 18 for the rectangle:
// msm_rect_light_facing_fraction of the kept extents).
DirectionalLight light_of_area_light(const msm::MsmAreaLight& area);
// A probe light with its sub-lights (msm::probe::ProbeLight), each made by light_of_area_light.
DirectionalLight light_of_probe_light(const msm::probe::ProbeLight& light);

// The shading's shortcut for a light's sub-lights (shading.glsl, sub_lights_irradiance): their
// irradiance by direction Σ_k E_k l_kᵀ, and a rectangle of tangents about the light's direction
// that holds every sub-light as msm_light_cosine shades it (the light frame's axes, bounds by
// msm_light_tangent_bounds; −1: none). Where msm_tangent_rect_side says a unit normal n has that
// rectangle above its horizon, every sub-light is wholly above it and their summed cosine
// integrals are msm_linear_irradiance(irradiance_by_direction, n); where below, they are 0.
struct SubLightsLinearPart {
  glm::mat3 irradiance_by_direction{0.0f};
  glm::vec3 x_axis{1.0f, 0.0f, 0.0f}, y_axis{0.0f, 1.0f, 0.0f};
  glm::vec2 bounds{-1.0f};
};
SubLightsLinearPart sub_lights_linear_part(const DirectionalLight& light);

// Image-based lighting: the probe the scene's area lights were made from (Scene::lights holds them).
struct ProbeLighting {
  std::filesystem::path file; // "sky": the procedural sky
  int lights = 32;
  float intensity = 1.0f;
  float rotation_deg = 0.0f;
  int size = 128;
  bool horizon_split = false; // the median cut's horizon split (msm::probe::median_cut): lights >= 10, size even
  // Above `lights`: every light gets the lights of the cut into sub_lights regions that lie in its
  // region as sub-lights (DirectionalLight::sub_lights, msm::probe::sub_regions); 0 or at most
  // `lights`: none (each light would be its own single sub-light).
  int sub_lights = 0;
  std::size_t first_light = 0; // index of its first light in Scene::lights
};

struct ShadowFraming {
  // fit: to what the camera sees (fit_light_frustum); fit_scene: to every vertex; given: explicit.
  enum class Mode { fit, fit_scene, given } mode = Mode::fit;
  glm::vec3 center{0.0f};
  glm::vec2 extent{1.0f};
  glm::vec2 depth_range{-1.0f, 1.0f};
};

// The orthographic shadow-map frustum of one directional light with the scene's framing: the one
// definition the renderer (its light uniforms) and the ray tracer (kernel offsets, light axes)
// derive their light-space quantities from.
struct LightFrame {
  glm::mat4 view_projection{1.0f}; // world -> clip: x, y in [-1, 1] (y down the map), depth in [0, 1]
  glm::dvec3 towards_light{0.0, 1.0, 0.0};
  // Unit world directions of increasing clip x / y (along the map's texel rows / columns; clip y
  // points down the image); both orthogonal to towards_light.
  glm::dvec3 x_axis{1.0, 0.0, 0.0}, y_axis{0.0, 0.0, 1.0};
  glm::dvec2 extent{1.0, 1.0}; // the frustum's width and height in world units
  double depth_extent = 1.0;   // world distance from depth 0 to depth 1
  // One texel of a shadow map of shadow_size² texels, in world units along x_axis and y_axis.
  glm::dvec2 texel(int shadow_size) const { return extent / double(shadow_size); }
};

struct Scene {
  std::string name;             // "name", else a scene file's stem
  std::filesystem::path source; // the scene file, or "builtin:<name>"
  std::vector<Material> materials;
  std::vector<Object> objects;
  Camera camera;
  // Shadow-casting directional lights (the JSON's "light", the directional ones of "lights", a
  // glTF object's imported ones, then the probe's); this and local_lights together hold at least
  // one light. The ray tracer's effects for directional lights use the first: light().
  std::vector<DirectionalLight> lights{DirectionalLight{}};
  // The spot and point lights of "lights", in their order there (directional ones + these <=
  // kMaxLights). A scene may have these only: then `lights` is empty and light() must not be called.
  std::vector<LocalLight> local_lights;
  ShadowFraming shadow;
  std::optional<Medium> medium;       // the JSON's "medium"; none: clear air
  std::optional<ProbeLighting> probe; // the JSON's "probe"; its lights follow the directional ones

  const DirectionalLight& light() const { return lights.front(); } // precondition: !lights.empty()
  // The number of lights of a kind (the probe's area lights are directional).
  std::size_t light_count(LightKind kind) const;
  // Some object has a "motion": its frames differ (at_frame).
  bool animated() const;

  Bounds bounds() const;
  std::size_t triangle_count() const;
  std::size_t vertex_count() const;
  // Light view (right-handed, looking along travel()) and orthographic projection of lights[index],
  // with the shadow framing applied: fit_light_frustum's box for "fit" and "fit_scene", the explicit
  // box for "explicit". O(vertices) per call: cache the result. Vulkan clip conventions.
  // Precondition: index < lights.size().
  glm::mat4 light_view(std::size_t index = 0) const { return light_view(lights.at(index)); }
  glm::mat4 light_projection(std::size_t index = 0) const { return light_projection(lights.at(index)); }
  glm::mat4 light_view_projection(std::size_t index = 0) const { return light_projection(index) * light_view(index); }
  LightFrame light_frame(std::size_t index = 0) const { return light_frame(lights.at(index)); }
  // The same for any light (e.g. the renderer's per-frame lights), with the scene's framing.
  glm::mat4 light_view(const DirectionalLight& light) const;
  glm::mat4 light_projection(const DirectionalLight& light) const;
  LightFrame light_frame(const DirectionalLight& light) const;
  glm::mat4 camera_view_projection(float aspect) const { return camera.projection(aspect) * camera.view(); }
};

// ---- Framing --------------------------------------------------------------------------------

// The widest image (width / height) the "fit" framing serves: the camera's frustum is taken at
// this aspect, so any narrower image sees only surfaces inside the map.
inline constexpr float kFitMaxAspect = 2.4f;

// An orthographic box in light view space (as glm::orthoRH_ZO takes it: x in [lo.x, hi.x], y in
// [lo.y, hi.y], distance along the light's travel in [-hi.z, -lo.z]).
struct LightBox {
  glm::vec3 lo{-1.0f}, hi{1.0f};
  bool visible_only = false; // fitted to the visible part (else to every vertex)
};

// The "fit" framing. visible_only: x and y span the intersection of the camera's view frustum (at
// kFitMaxAspect) with the scene's bounds, the part of the scene the camera can see; depth runs from
// the vertex closest to the light among those over that rectangle (the casters; a caster nearer
// still is clamped to depth 0 by the renderer and still shadows) to the farthest visible point.
// Otherwise, or where the frustum misses the bounds, every vertex maps into x, y in [-1, 1] and
// depth [0, 1] (depth 0 at the vertex closest to the light, 1 at the farthest). A relative margin
// of 1e-5 of the scene's size keeps rounding from pushing points out.
LightBox fit_light_frustum(const Scene& scene, const glm::mat4& light_view, bool visible_only);

// ---- Cascaded shadow maps (docs/techniques.md, "Cascades") ----------------------------------

// A directional light's map split along the camera's view depth into 1..kMaxCascades maps, each
// covering a slice of the view frustum: nearer slices are smaller, so their texels are finer.
inline constexpr int kMaxCascades = 8;
// The practical split scheme's default blend, towards the logarithmic split: a view depth range of a
// few hundred times the nearest visible surface's distance still gets a near cascade fine enough.
inline constexpr double kDefaultCascadeLambda = 0.9;

struct CascadeOptions {
  int count = 1;                         // 1..kMaxCascades
  double lambda = kDefaultCascadeLambda; // the practical split scheme's blend: 0 uniform, 1 logarithmic
  // Stabilisation: the bounding sphere's radius rounded up to 1/16 unit and its centre snapped to
  // whole texels of the light's map, so a camera that moves or turns moves no texel edge.
  bool stabilize = true;
  double blend = 0.1; // the band at each cascade's far end where it fades into the next, as a fraction of its slice
  // The view depths [near, far] the splits divide: where set, what the camera's depth buffer holds
  // (the renderer's reduction, sample-distribution shadow maps); unset, visible_depth_range's
  // estimate from the scene's bounds. Clamped to the camera's near and far planes either way.
  std::optional<glm::dvec2> depth_range = std::nullopt;
};

// One cascade: its orthographic map and the view depths where it is used, a weight rising from 0 at
// fade_in.x to 1 at fade_in.y and falling back to 0 from fade_out.x to fade_out.y (the next
// cascade's rise over the same band: the weights sum to 1). The first has no rise, the last no fall.
struct Cascade {
  LightFrame frame;
  glm::dvec2 fade_in{-1e30, -1e30}, fade_out{1e30, 1e30};
};

// The split distances (count + 1 view depths, first `near`, last `far`) of the practical scheme:
// lambda times the logarithmic split plus (1 - lambda) times the uniform one.
std::vector<double> cascade_splits(double near, double far, int count, double lambda);

// The view depths [near, far] of what the camera can see of the scene: its view frustum (at
// kFitMaxAspect) clipped to the scene's bounds, within the camera's near and far planes.
glm::dvec2 visible_depth_range(const Scene& scene);

// The cascades of a directional light for a map of shadow_size² texels per cascade: each fitted to
// the bounding sphere of its slice of the view frustum (its band with the previous one included),
// depth from the casters over it (the light's nearest vertex there) to the sphere's far side. The
// slices split options.depth_range, else visible_depth_range(scene).
std::vector<Cascade> fit_cascades(const Scene& scene, const DirectionalLight& light, int shadow_size,
                                  const CascadeOptions& options);

// The frame of an orthographic light view-projection (Scene::light_frame's definition).
LightFrame orthographic_light_frame(const glm::mat4& view_projection, const glm::vec3& towards_light);

// How coarse the shadow map is on screen: one texel (the larger of its two sides, in scene units)
// over the size of a pixel at the nearest surface inside the view frustum (view depth `distance`;
// pixels per unit there: height / (2 distance tan(fov_y / 2))), for an image of width x height and
// a map of shadow_size² texels.
struct TexelCoverage {
  bool visible = false;           // the camera sees a surface
  double pixels_per_texel = 0.0;  // screen pixels one texel spans (along a line)
  double texel_size = 0.0;        // scene units
  double distance = 0.0;          // view depth of the nearest visible surface
  glm::vec3 where{0.0f};          // a point of it
  bool aspect_beyond_fit = false; // "fit" framing and width / height > kFitMaxAspect
};
// With cascades (cascades.count > 1; fit_cascades), the texel of the cascade whose slice holds the
// nearest visible surface.
TexelCoverage shadow_texel_coverage(const Scene& scene, int width, int height, int shadow_size,
                                    const CascadeOptions& cascades = {});

// Above this many screen pixels per shadow-map texel the tools warn.
inline constexpr double kMaxPixelsPerTexel = 8.0;

// Where a light's shadow map holds nothing that matters, for an image of width x height: the map's
// box (x, y in [-1, 1], depth at most 1: what the shading looks up; nearer casters are clamped to
// depth 0 and still cast) meets none of the surfaces inside the camera's view frustum (visible
// receivers: none can be shadowed), or none of the scene's triangles at all (casters: no shadow).
// Checked for explicit framing only: the fitted ones contain the scene by construction.
struct FramingMiss {
  std::size_t light = 0;
  bool receivers = false; // the map holds no visible receiver
  bool casters = false;   // the map holds no caster
};
std::vector<FramingMiss> shadow_framing_misses(const Scene& scene, int width, int height);

// The warnings the tools print and write into their JSON "warnings", one string each (none: empty):
// when a texel (of the cascades where `cascades` has several) spans more than kMaxPixelsPerTexel
// pixels (naming the cures: more cascades, a larger map, explicit framing), when the image is wider
// than the fit covers, and for each light whose framing misses the visible receivers or the casters
// (shadow_framing_misses).
std::vector<std::string> shadow_framing_warnings(const Scene& scene, int width, int height, int shadow_size,
                                                 const CascadeOptions& cascades = {});
// The same joined by newlines, or none.
std::optional<std::string> shadow_framing_warning(const Scene& scene, int width, int height, int shadow_size,
                                                  const CascadeOptions& cascades = {});

// Loading. Relative mesh/texture paths resolve against base_dir (the file's directory).
Scene load_scene_file(const std::filesystem::path& file);
Scene load_scene_json(std::string_view json_text, const std::filesystem::path& base_dir,
                      const std::string& source_name);

// Built-in scenes (scenes/README.md): "fence" (the default), "railing", "stair", "column", "smoke",
// "models", "pillar_wall", "disc", "glass"; with a medium (single scattering): "tower", "trees",
// "gate", "room".
std::vector<std::string> builtin_scene_names();
std::string_view default_scene_name();                      // "fence"
std::string_view builtin_scene_json(std::string_view name); // throws SceneError if unknown
Scene builtin_scene(std::string_view name);
// A built-in name, or else a path to a scene file.
Scene load_scene(std::string_view name_or_path);
// Replaces the probe's area lights by a median cut into `count` (1..256), as "probe": {"lights":
// count} would have made them (`msm render --lights`). SceneError without a probe, for a count out of
// range or beyond kMaxLights with the other lights. sub_lights, where given, replaces the probe's
// "sub_lights" (`msm render --sub-lights`; 0..256, at least 10 with the horizon split).
void set_probe_light_count(Scene& scene, int count, std::optional<int> sub_lights = std::nullopt);

// Lights the scene by the light probe `file` (an equirectangular EXR, a cube-map cross, six faces
// named by a "{face}" path, or "sky")
// instead of its own lighting (`msm render --probe`, `msm reference --probe`): its lights (every
// kind) and its probe's lights are replaced by the new probe's area lights. The scene's probe
// settings (lights, size, intensity, rotation, horizon split, sub-lights) are kept where it has a
// probe, else ProbeLighting's defaults (32 lights, 128² per face). SceneError naming the file for a
// missing or unreadable probe, or one without light.
void set_probe(Scene& scene, const std::filesystem::path& file);

// The scene at frame `frame` (>= 0) of its animation: every object with a motion turned by frame ×
// its angle about its axis through its origin, then moved by frame × its translation (vertices,
// normals, bounds and transform); frame 0 is the scene itself. What the renderer draws
// (Renderer::move_objects) and the ray tracer traces at that frame. The probe's lights are kept
// (its per-frame rotation is the renderer's, `msm render --probe-rotation-speed`).
Scene at_frame(const Scene& scene, int frame);

// Mesh import through Assimp: node transforms applied (instances repeated), triangulated, texture
// coordinates flipped to v down where the format has v up, KHR_texture_transform baked into them,
// normals generated if missing, degenerate triangles dropped. Object space. Throws SceneError.
Mesh import_mesh(const std::filesystem::path& file);

// The same file as one part per material, each with the file's material (glTF: base colour
// factor and texture, alphaMode OPAQUE / MASK with alphaCutoff / BLEND, doubleSided,
// KHR_materials_transmission's factor; other formats: diffuse colour and texture, opacity,
// two-sidedness; scenes/README.md says what is read). Textures embedded in the file (GLB, data
// URIs) are decoded here; referenced files must exist. A part without a material of its own
// (Assimp's default material) has none.
struct ModelPart {
  std::string name; // the material's name in the file, or "part<i>"
  Mesh mesh;        // object space
  std::optional<Material> material;
};
std::vector<ModelPart> import_model(const std::filesystem::path& file);

// Primitive generators (local frames as documented above). Arguments are validated.
Mesh make_plane(glm::vec2 size, glm::ivec2 subdivisions = {1, 1});
Mesh make_box(glm::vec3 size);
Mesh make_sphere(float radius, int segments = 64, int rings = 32);
Mesh make_cylinder(float radius, float height, int segments = 64, bool caps = true);
Mesh make_fence(float length, float height, int bars, float bar_width, float bar_depth, int rails, float rail_height);
Mesh make_stair(int steps, float width, float step_depth, float step_height);
Mesh make_torus_knot(int p, int q, float radius, float tube_radius, int segments, int tube_segments);
Mesh make_brick_wall(int rows, int columns, float brick_length, float brick_height, float mortar, float relief,
                     float thickness);

// Minimal lazy texture loading (stb_image), always 4 channels RGBA8.
Image load_texture(const std::filesystem::path& file);
// The albedo texture of a material (its embedded texels, or load_texture of its file); width 0
// if it has none.
Image albedo_image(const Material& material);

// The opacity texture of a material (from its file or its procedural noise), as 8-bit values
// (the alpha channel of the file, or its red channel where alpha is all 255); width 0 if none.
// The renderer uploads it and the ray tracer samples it (bilinear, repeat), so both see the same
// opacity.
struct OpacityImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> values;
  float sample(glm::vec2 uv) const; // bilinear with repeat, in [0, 1]; 1 if empty
};

// Bilinear interpolation with repeat over a width x height grid of texels, texel centres at
// ((i + 0.5) / width, (j + 0.5) / height), as a Vulkan linear sampler with REPEAT addressing;
// fetch(i, j) returns texel (i, j) (row j from the top). The one formula the CPU samplers share.
template <class T, class Fetch>
T sample_bilinear_repeat(int width, int height, glm::vec2 uv, Fetch&& fetch) {
  const float x = uv.x * float(width) - 0.5f, y = uv.y * float(height) - 0.5f;
  const float fx = glm::floor(x), fy = glm::floor(y);
  const auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  const int i = int(fx), j = int(fy);
  const int i0 = wrap(i, width), i1 = wrap(i + 1, width), j0 = wrap(j, height), j1 = wrap(j + 1, height);
  const float tx = x - fx, ty = y - fy;
  return (1 - ty) * ((1 - tx) * fetch(i0, j0) + tx * fetch(i1, j0)) +
         ty * ((1 - tx) * fetch(i0, j1) + tx * fetch(i1, j1));
}
OpacityImage opacity_image(const Material& material);
// 128² procedural smoke: deterministic for its parameters.
OpacityImage make_smoke_opacity(const SmokeNoise& noise);

} // namespace msm::scene
