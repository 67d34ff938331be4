// Light probes as cube maps and the area lights a median cut makes of them (Kneiphof, "Real-Time
// Image-Based Lighting of Dynamic Scenes with Moment Soft Shadow Mapping", 2017, §4.1), written
// once for the device and the CPU reference.
//
// Cube-map conventions are Vulkan's (spec, "Cube Map Face Selection"): faces +X, −X, +Y, −Y, +Z,
// −Z are layers 0..5; on a face, u = s_c / |m_a| and v = t_c / |m_a| in [−1, 1], with texel row 0
// at v = −1 (image rows run along +v). A texel (i, j) of an m x m face has its centre at
// u = (2 i + 1) / m − 1, v = (2 j + 1) / m − 1.
#ifndef MSM_LIGHT_PROBE_H
#define MSM_LIGHT_PROBE_H
#include "msm/shading.h"

MSM_BEGIN

// The unnormalized direction through (u, v) of a face: the point of the face's plane at distance 1
// from the centre (|result| = sqrt(1 + u² + v²)).
MSM_FN vec3 msm_cube_direction(int face, float u, float v) {
  if (face == 0) return vec3(1.0f, -v, -u);
  if (face == 1) return vec3(-1.0f, -v, u);
  if (face == 2) return vec3(u, 1.0f, v);
  if (face == 3) return vec3(u, -1.0f, -v);
  if (face == 4) return vec3(u, -v, 1.0f);
  return vec3(-u, -v, -1.0f);
}

// The world directions of increasing u and of increasing v on a face (∂ msm_cube_direction / ∂u, ∂v).
MSM_FN vec3 msm_cube_u_axis(int face) {
  if (face == 0) return vec3(0.0f, 0.0f, -1.0f);
  if (face == 1) return vec3(0.0f, 0.0f, 1.0f);
  if (face == 5) return vec3(-1.0f, 0.0f, 0.0f);
  return vec3(1.0f, 0.0f, 0.0f);
}
MSM_FN vec3 msm_cube_v_axis(int face) {
  if (face == 2) return vec3(0.0f, 0.0f, 1.0f);
  if (face == 3) return vec3(0.0f, 0.0f, -1.0f);
  return vec3(0.0f, -1.0f, 0.0f);
}

// Face and face coordinates of a direction (the inverse of msm_cube_direction up to scale). Ties
// between faces go to the lower layer. Precondition: d != 0.
struct MsmCubeCoord {
  int face;
  vec2 uv;
};
MSM_FN MsmCubeCoord msm_cube_coord(vec3 d) {
  vec3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z)
    return d.x >= 0.0f ? MsmCubeCoord(0, vec2(-d.z, -d.y) / a.x) : MsmCubeCoord(1, vec2(d.z, -d.y) / a.x);
  if (a.y >= a.z) return d.y >= 0.0f ? MsmCubeCoord(2, vec2(d.x, d.z) / a.y) : MsmCubeCoord(3, vec2(d.x, -d.z) / a.y);
  return d.z >= 0.0f ? MsmCubeCoord(4, vec2(d.x, -d.y) / a.z) : MsmCubeCoord(5, vec2(-d.x, -d.y) / a.z);
}

// The texel (column, row, face) of an m x m face cube map that direction d falls in: what the
// renderer and the ray tracer show as the background of a probe-lit scene (nearest texel, so that
// both show the same value). Precondition: d != 0, m >= 1.
MSM_FN ivec3 msm_cube_texel(vec3 d, int m) {
  MsmCubeCoord c = msm_cube_coord(d);
  ivec2 t = clamp(ivec2(floor((c.uv + 1.0f) * (0.5f * float(m)))), ivec2(0), ivec2(m - 1));
  return ivec3(t.x, t.y, c.face);
}

// The solid angle a texel at (u, v) of an m x m face subtends, to first order: the density
// (1 + u² + v²)^(−3/2) (Kneiphof Eq. 8 with the sign of the exponent the extracted text lost; see
// ERRATA.md) times the texel's area 4 / m² on the face. Summed over the six faces: 4π.
MSM_FN float msm_cube_texel_weight(float u, float v, float m) {
  float r2 = 1.0f + u * u + v * v;
  return 4.0f / (m * m * r2 * sqrt(r2));
}

// The face coordinate (u or v) of the point at `offset` in [0, 1] across texel i of a face of
// `size` texels (offset 0.5: the texel's centre).
MSM_FN float msm_cube_face_coordinate(int i, float offset, float size) {
  return (2.0f * (float(i) + offset)) / size - 1.0f;
}

// --- Equirectangular panorama -> cube map (msm::probe::cube_from_equirect and the device's
// probe_cube.comp): each cube texel averages ss² bilinear point samples of the panorama. ---

// The panorama point (s, t) in [0, 1]² of a direction (precondition: d != 0): azimuth
// φ = atan2(x, −z) about +Y (φ = 0 along −Z, increasing towards +X) at s = (φ + π) / 2π, polar
// angle θ from +Y at t = θ / π. θ = atan2(sqrt(x² + z²), y), not acos(y / |d|), which loses
// half the digits near the poles (acos(1 − ε) ≈ sqrt(2ε)); neither needs d normalized.
MSM_FN vec2 msm_equirect_of(vec3 d) {
  float phi = atan(d.x, -d.z);
  float theta = atan(length(vec2(d.x, d.z)), d.y);
  return vec2((phi + MSM_PI) / MSM_TWO_PI, theta / MSM_PI);
}

// Where a world direction looks the probe up when the probe is turned by an angle whose cosine
// and sine are cos_sin about +Y (counter-clockwise seen from above): the direction turned back.
MSM_FN vec3 msm_probe_lookup_direction(vec3 d, vec2 cos_sin) {
  return vec3(cos_sin.x * d.x - cos_sin.y * d.z, d.y, cos_sin.y * d.x + cos_sin.x * d.z);
}

// The bilinear footprint of panorama point st on a width x height panorama: texel p0 and its
// neighbours p0 + (1, 0), (0, 1), (1, 1), weighted by the fractions f.
struct MsmBilinearTap {
  ivec2 p0;
  vec2 f;
};
MSM_FN MsmBilinearTap msm_equirect_tap(vec2 st, ivec2 size) {
  float x = st.x * float(size.x) - 0.5f, y = st.y * float(size.y) - 0.5f;
  float fx = floor(x), fy = floor(y);
  return MsmBilinearTap(ivec2(int(fx), int(fy)), vec2(x - fx, y - fy));
}
// A texel of a tap's footprint on the panorama: wrapping in longitude, clamped in latitude.
// Precondition: −1 <= p.x <= width (what msm_equirect_tap gives for s in [0, 1]).
MSM_FN ivec2 msm_equirect_texel(ivec2 p, ivec2 size) {
  int x = p.x < 0 ? p.x + size.x : (p.x >= size.x ? p.x - size.x : p.x);
  return ivec2(x, clamp(p.y, 0, size.y - 1));
}
MSM_FN vec3 msm_bilinear(vec3 a00, vec3 a10, vec3 a01, vec3 a11, vec2 f) {
  return (1.0f - f.y) * ((1.0f - f.x) * a00 + f.x * a10) + f.y * ((1.0f - f.x) * a01 + f.x * a11);
}

// a.x b.x + a.y b.y + a.z b.z in this order, nothing fused: the same bits on every device.
MSM_FN float msm_dot_in_order(vec3 a, vec3 b) {
  MSM_PRECISE float r = a.x * b.x + a.y * b.y + a.z * b.z;
  return r;
}

// CIE XYZ of linear Rec. 709 RGB (Y = msm_luminance): the median cut splits by luminance and its
// tables keep X, Y, Z (Kneiphof §5: Y is the luminance, X and Z carry the colour back). Every
// component is summed in a fixed order (the fixed-point tables below need the same bits everywhere).
MSM_FN vec3 msm_rgb_to_xyz(vec3 c) {
  return vec3(msm_dot_in_order(c, vec3(0.4124f, 0.3576f, 0.1805f)), msm_luminance(c),
              msm_dot_in_order(c, vec3(0.0193f, 0.1192f, 0.9505f)));
}
MSM_FN vec3 msm_xyz_to_rgb(vec3 c) {
  return vec3(dot(c, vec3(3.2406f, -1.5372f, -0.4986f)), dot(c, vec3(-0.9689f, 1.8758f, 0.0415f)),
              dot(c, vec3(0.0557f, -0.2040f, 1.0570f)));
}

// Sums over the texels of one region of one face, each texel weighted by its solid angle
// (msm_cube_texel_weight): xyz = Σ w L_XYZ (so y is the region's illuminance from luminance and
// xyz its irradiance M_e of Eq. 11, in XYZ), and the luminance-weighted first and second moments
// of the face coordinates, Σ w Y (u, v) and Σ w Y (u², v²).
struct MsmRegionSums {
  vec3 xyz;
  vec2 first;
  vec2 second;
};

// --- Fixed-point probe tables (msm::probe::ProbeTables on the CPU, probe_table_rows.comp on the
// device). The median cut must make the same regions on the device and the CPU, so its tables are
// integers: every texel's seven values below are scaled by a power of two `scale` (chosen on the
// host from the probe's largest component, msm::probe::table_scale, so that a face's sums fit in
// 64 bits) and truncated to uint64; integer sums are exact in any order, so both tables are equal
// bit for bit when the texel values are. They are: each product and sum rounds once in a fixed
// order (MSM_PRECISE), and the weight w and the coordinates u, v come from the host
// (msm_cube_texel_weight and msm_cube_face_coordinate evaluated there), as the device's division
// and square root need not round correctly. ---

// One texel's values times scale: a = (w X, w Y, w Z, w Y (1 + u)), b = (w Y (1 + v), w Y u²,
// w Y v²). The first moments are kept shifted by the region's energy (w Y (1 + u) >= 0) so that
// they are unsigned; msm_region_sums_from_fixed shifts them back.
struct MsmProbeTexel {
  vec4 a;
  vec3 b;
};
MSM_FN MsmProbeTexel msm_probe_texel(vec3 rgb, float w, float u, float v, float scale) {
  vec3 xyz = msm_rgb_to_xyz(rgb);
  MSM_PRECISE float wx = (w * xyz.x) * scale;
  MSM_PRECISE float wy = w * xyz.y;
  MSM_PRECISE float wz = (w * xyz.z) * scale;
  MSM_PRECISE float fu = (wy * (1.0f + u)) * scale;
  MSM_PRECISE float fv = (wy * (1.0f + v)) * scale;
  MSM_PRECISE float su = ((wy * u) * u) * scale;
  MSM_PRECISE float sv = ((wy * v) * v) * scale;
  MSM_PRECISE float sy = wy * scale;
  return MsmProbeTexel(vec4(wx, sy, wz, fu), vec3(fv, su, sv));
}

// A region's MsmRegionSums from its fixed-point sums, converted to float after the integer
// differences: xyz = (Σ w X, Σ w Y, Σ w Z), first = (Σ w Y (1 + u), Σ w Y (1 + v)) − Σ w Y, second
// = (Σ w Y u², Σ w Y v²), all times scale; inv_scale = 1 / scale.
MSM_FN MsmRegionSums msm_region_sums_from_fixed(vec3 xyz, vec2 first, vec2 second, float inv_scale) {
  return MsmRegionSums(xyz * inv_scale, first * inv_scale, second * inv_scale);
}

// --- Rectangular area lights (Kneiphof §4.1.2): the directions ℓ + a x + b y with (a, b) in
// [−t.x, t.x] × [−t.y, t.y] (x, y unit and orthogonal to ℓ: a planar emitter at infinity, the
// model of soft.h and of the ray tracer), t the tangents of the half angles, radiance uniform in
// solid angle. On the plane at unit distance dω = dA / r³ and d·ℓ = 1 / r, r = sqrt(1 + a² + b²).
// One definition for the renderer (its shading cone), the scene's lights (their irradiance) and
// the ray tracer (its samples' weights). ---

// Solid angle Ω = ∫ dA / r³ of the rectangle (the closed form of a rectangle seen from a point
// above its corner, four times).
MSM_FN float msm_rect_light_solid_angle(vec2 t) { return 4.0f * atan(t.x * t.y / sqrt(1.0f + t.x * t.x + t.y * t.y)); }

// F = ∫ (d·ℓ) dω = ∫ dA / r⁴: the irradiance of radiance 1 on a surface facing the light.
MSM_FN float msm_rect_light_facing_integral(vec2 t) {
  float rx = sqrt(1.0f + t.x * t.x), ry = sqrt(1.0f + t.y * t.y);
  return 2.0f * (t.x / rx * atan(t.y / rx) + t.y / ry * atan(t.x / ry));
}

// F / Ω: the irradiance on a facing surface per unit of the light's M_e = L Ω (Eq. 16 for the
// rectangle); 1 in the point-light limit, where both vanish (F / Ω = 1 − (t.x² + t.y²) / 6 + …).
MSM_FN float msm_rect_light_facing_fraction(vec2 t) {
  float omega = msm_rect_light_solid_angle(t);
  if (omega < 1e-6f) return 1.0f - (t.x * t.x + t.y * t.y) / 6.0f;
  return msm_rect_light_facing_integral(t) / omega;
}

// The half-angle α of the cone of the rectangle's solid angle, 2π (1 − cos α) = Ω: the disc of the
// rectangle's size (MsmAreaLight::cone_half_angle, LightUniforms::soft.z); the shading integrates
// the rectangle itself at the horizon (msm_rect_light_cosine). α = 2 asin(sqrt(Ω / 4π)), which
// keeps its digits for small lights (acos(1 − Ω / 2π) would not).
MSM_FN float msm_rect_light_cone_half_angle(vec2 t) {
  return 2.0f * asin(min(sqrt(msm_rect_light_solid_angle(t) / (4.0f * MSM_PI)), 1.0f));
}

// A rectangular area light made from a region (Kneiphof §4.1.2–4.1.3).
struct MsmAreaLight {
  vec3 direction;        // unit, from the scene towards the light: the luminance-weighted mean direction
                         // (Eq. 9 on the sphere, msm_region_mean_direction)
  vec3 x_axis, y_axis;   // unit, orthogonal to direction: the face's u and v axes projected (§4.1.2)
  vec2 half_extent;      // half extents along x_axis / y_axis as tangents of angles
  float cone_half_angle; // α_A of the circular light of the same solid angle as the rectangle (not
                         // what the shading integrates: msm_rect_light_cosine clips the rectangle)
  vec3 irradiance;       // M_e (Eq. 11), linear RGB: the light's Σ w L over its region
};

// The luminance-weighted mean of a region's unit directions, E[(u, v, 1) / r] with r = sqrt(1 +
// u² + v²) in the face's frame (u axis, v axis, face normal), up to a positive factor: the
// direction whose cosine law n·z gives a region above a receiver's horizon its exact irradiance
// (∫ L n·ω dω = n·∫ L ω dω). The tables hold the luminance-weighted moments of u and v, not of the
// unit directions, so it is Taylor's expansion to second order about the centroid (μ_u, μ_v) with
// the variances σ_u², σ_v² (the covariance is not tabulated: taken 0, as §4.1.2 takes the axes
// independent), times r⁵ (a positive factor; the caller normalizes):
// r⁴ (μ_u, μ_v, 1) + ½ σ_u² r⁵ ∂²/∂u² + ½ σ_v² r⁵ ∂²/∂v², with
// r⁵ ∂²/∂u² (u, v, 1) / r = (−3u (1 + v²), v (2u² − v² − 1), 2u² − v² − 1) and ∂²/∂v² alike.
// Eq. (9)'s centroid on the face plane, projected, lies outwards of it (the plane's points
// spread further than their directions): 1.4° for a quarter of a face, 4% of that light's
// irradiance on a receiver it grazes; this estimate comes within 0.1° of the exact mean
// (docs/results.md, "The sphere's centroid").
MSM_FN vec3 msm_region_mean_direction(int face, vec2 mean, vec2 variance) {
  float u = mean.x, v = mean.y;
  float r2 = 1.0f + u * u + v * v;
  vec3 second_u = vec3(-3.0f * u * (1.0f + v * v), v * (2.0f * u * u - v * v - 1.0f), 2.0f * u * u - v * v - 1.0f);
  vec3 second_v = vec3(u * (2.0f * v * v - u * u - 1.0f), -3.0f * v * (1.0f + u * u), 2.0f * v * v - u * u - 1.0f);
  vec3 f = r2 * r2 * vec3(u, v, 1.0f) + 0.5f * (variance.x * second_u + variance.y * second_v);
  // The mean of directions through a face lies in the face's cone |x|, |y| <= z; the truncated
  // series can leave it for light spread to opposite edges (f.z -> 0 at σ² = 1): kept inside.
  f.z = max(f.z, max(max(abs(f.x), abs(f.y)), 1e-3f));
  return f.x * msm_cube_u_axis(face) + f.y * msm_cube_v_axis(face) + f.z * msm_cube_direction(face, 0.0f, 0.0f);
}

// The area light of a region of `face` from its sums (precondition: sums.xyz.y > 0). Its
// direction is the region's mean direction (msm_region_mean_direction: Eq. (9)'s luminance-
// weighted centroid taken on the sphere rather than on the face plane). The variances
// σ² = E[u²] − μ² about the centroid (μ_u, μ_v) give half extents d = sqrt(3 σ²) (the uniform
// distribution of the same variance; ERRATA.md corrects the text's σ² = d / 3) on the face plane.
// The paper scales them by the length of the projected face axis; here they are also divided by
// the distance from the centre of the face plane's point in the light's direction, so that they
// are tangents of angles wherever on the face the region lies. The circular light has the solid angle
// of the rectangle (msm_rect_light_cone_half_angle). Where the light dips below a receiver's
// horizon (Eq. 15's π sin² α cos no longer holds, and would go negative), the shading integrates
// the cosine over the part of the rectangle above the horizon (msm_rect_light_cosine: the rectangle
// clipped by the horizon plane, Lambert's edge formula), n·ℓ where it is all above, 0 all below.
MSM_FN MsmAreaLight msm_area_light_from_region(int face, MsmRegionSums sums) {
  float total = sums.xyz.y;
  vec2 mean = sums.first / total;
  vec2 variance = max(sums.second / total - mean * mean, vec2(0.0f));
  vec2 d = sqrt(3.0f * variance);
  vec3 z = normalize(msm_region_mean_direction(face, mean, variance));
  float distance = 1.0f / dot(z, msm_cube_direction(face, 0.0f, 0.0f));
  vec3 x = msm_cube_u_axis(face), y = msm_cube_v_axis(face);
  x -= z * dot(x, z);
  y -= z * dot(y, z);
  float x_length = length(x), y_length = length(y);
  vec2 t = d * vec2(x_length, y_length) / distance;
  float cone = msm_rect_light_cone_half_angle(t);
  return MsmAreaLight(z, x / x_length, y / y_length, t, cone, max(msm_xyz_to_rgb(sums.xyz), vec3(0.0f)));
}

// --- Regions of several faces (N < 6: msm::probe::median_cut merges the six face regions, see
// docs/techniques.md). The light of such a region is made from the lights of its parts, one per
// face (msm_area_light_from_region of the part's sums), added in increasing face order by
// msm_merged_sums_add (the CPU's area_lights and probe_cut.comp call the same functions in the same
// order). Each part r of energy E_r = Σ w Y is taken as its light: a direction z_r with a uniform
// spread of tangent variances σ² = t² / 3 along x_r, y_r (the inverse of d = sqrt(3σ²)). ---
struct MsmMergedSums {
  vec3 xyz;       // Σ of the parts' Σ w L_XYZ: the region's M_e (Eq. 11) in XYZ
  vec3 mean;      // Σ E_r z_r
  mat3 second;    // Σ E_r (z_r z_rᵀ + σ_x² x_r x_rᵀ + σ_y² y_r y_rᵀ)
  float dominant; // E_r of the most energetic part so far (ties: the first)
  vec3 dominant_z, dominant_x, dominant_y;
};
MSM_FN MsmMergedSums msm_merged_sums_empty() {
  return MsmMergedSums(vec3(0.0f), vec3(0.0f), mat3(0.0f), 0.0f, vec3(0.0f, 0.0f, 1.0f), vec3(1.0f, 0.0f, 0.0f),
                       vec3(0.0f, 1.0f, 0.0f));
}
MSM_FN MsmMergedSums msm_merged_sums_add(MsmMergedSums s, int face, MsmRegionSums part) {
  s.xyz += part.xyz;
  float e = part.xyz.y;
  if (!(e > 0.0f)) return s; // no light: no direction, no extent
  MsmAreaLight l = msm_area_light_from_region(face, part);
  vec2 variance = l.half_extent * l.half_extent / 3.0f;
  s.mean += e * l.direction;
  s.second += e * (outerProduct(l.direction, l.direction) + variance.x * outerProduct(l.x_axis, l.x_axis) +
                   variance.y * outerProduct(l.y_axis, l.y_axis));
  if (e > s.dominant) {
    s.dominant = e;
    s.dominant_z = l.direction;
    s.dominant_x = l.x_axis;
    s.dominant_y = l.y_axis;
  }
  return s;
}

// The light of a region of several parts (precondition: s.xyz.y > 0): the normalised
// luminance-weighted mean z of the parts' directions (each part's msm_region_mean_direction
// standing for its texels), or the most
// energetic part's direction where they cancel out (|Σ E_r z_r| < 10^-3 Σ E_r: light from all
// around has no direction); x the most energetic part's x axis projected off z (§4.1.2; its y axis
// crossed with z where x_r is along z), y = z × x; half extents d = sqrt(3σ²) from the variances
// about z, σ_x² = xᵀ second x / Σ E_r (an offset of a part counts by the sine of its angle to z, its
// spread by its own tangents: the same for small angles); the cone, as a face's, of the extents'
// rectangle's solid angle (msm_rect_light_cone_half_angle: below π/2, where msm_cone_cosine and
// Eqs. 15–18 hold; the parts' solid angles summed instead measured worse, docs/techniques.md); irradiance the summed
// M_e. One lit part alone gives its own direction, x axis and x extent.
MSM_FN MsmAreaLight msm_area_light_from_merged(MsmMergedSums s) {
  float total = s.xyz.y;
  float mean_length = length(s.mean);
  vec3 z = mean_length >= 1e-3f * total ? s.mean / mean_length : s.dominant_z;
  vec3 x = s.dominant_x - z * dot(s.dominant_x, z);
  if (length(x) < 1e-3f) x = cross(s.dominant_y, z);
  x = normalize(x);
  vec3 y = cross(z, x);
  vec2 variance = vec2(dot(x, s.second * x), dot(y, s.second * y)) / total;
  vec2 t = sqrt(3.0f * max(variance, vec2(0.0f)));
  float cone = msm_rect_light_cone_half_angle(t);
  return MsmAreaLight(z, x, y, t, cone, max(msm_xyz_to_rgb(s.xyz), vec3(0.0f)));
}

// ∫ over the cone of half-angle α around a light direction of max(cos, 0) dω, divided by the
// cone's π sin² α: the factor that replaces max(n·l, 0) for a uniform circular light, where
// cos_angle = n·l for the cone's axis l. Eq. (15) of the paper, π sin² α cos, holds while the whole
// cone is above the receiver's horizon (cos_angle >= sin α); below it, this is the exact integral
// over the part of the cone above the horizon (the form factor of a sphere or disc light, as in
// Lagarde and de Rousiers, "Moving Frostbite to PBR", 2014, §4.7.2), not the paper's formula,
// which would go negative; at cos_angle <= −sin α the light is below the horizon and it is 0.
MSM_FN float msm_cone_cosine(float cos_angle, float cone_half_angle) {
  float sin_a = sin(cone_half_angle);
  float sin2 = sin_a * sin_a;
  float c = clamp(cos_angle, -1.0f, 1.0f);
  if (c >= sin_a || sin2 <= 1e-8f) return max(c, 0.0f);
  if (c <= -sin_a) return 0.0f;
  float s = sqrt(max(1.0f - c * c, 0.0f));
  float x = sqrt(max(1.0f / sin2 - 1.0f, 0.0f)); // cot α
  float y = clamp(-x * c / s, -1.0f, 1.0f);
  float s_sqrt_y = s * sqrt(max(1.0f - y * y, 0.0f));
  float integral = (c * acos(y) - x * s_sqrt_y) * sin2 + atan(s_sqrt_y / x);
  return max(integral, 0.0f) / (MSM_PI * sin2);
}

// Corner i (mod 4) of the rectangle of half extents t, counter-clockwise from (−t.x, −t.y).
MSM_FN vec2 msm_rect_corner(int i, vec2 t) {
  int k = i % 4;
  return vec2(k == 1 || k == 2 ? t.x : -t.x, k >= 2 ? t.y : -t.y);
}

// Lambert's term of the arc between the directions P = (p, 1) and Q = (q, 1) for
// msm_rect_light_cosine, in the light's frame (x, y, ℓ): Θ n·normalize(P × Q), n = (n·x, n·y, n·ℓ),
// with Θ / |P × Q| -> 1 / (|P| |Q|) as the arc degenerates. The cross product is written out,
// P × Q = (p.y - q.y, q.x - p.x, p.x q.y - p.y q.x) = (-d.y, d.x, p.x d.y - p.y d.x) with d = q - p:
// formed from 3D vectors ℓ + a x + b y, a wide rectangle's nearly parallel long vectors (|a| ~
// 100) would cancel in every component (products of ~a² down to ~a), and the factor exceeded 1.
MSM_FN float msm_lambert_edge(vec3 n, vec2 p, vec2 q) {
  vec2 d = q - p;
  vec3 c = vec3(-d.y, d.x, p.x * d.y - p.y * d.x);
  float s = length(c), cos_term = dot(p, q) + 1.0f;
  float theta_per_s = s > 1e-12f ? atan(s, cos_term) / s : 1.0f / (sqrt(1.0f + dot(p, p)) * sqrt(1.0f + dot(q, q)));
  return theta_per_s * dot(n, c);
}

// ∫ over the rectangular light (the directions ℓ + a x + b y, |a| <= t.x, |b| <= t.y; radiance
// uniform in solid angle) of max(n·ω, 0) dω, divided by F = msm_rect_light_facing_integral(t): the
// factor that replaces max(n·l, 0) for the rectangle, exact at the horizon as msm_cone_cosine is
// for a disc. Where the whole rectangle is above the receiver's horizon it is n·ℓ (∫ ω dω over the
// rectangle is F ℓ by symmetry), where it is all below 0. Where it straddles the horizon, the
// rectangle is clipped in its own plane (the points ℓ + a x + b y) by the horizon plane n·p >= 0
// (a convex polygon of at most 5 vertices, taken edge by edge) and the clipped part integrated
// with Lambert's edge formula for a spherical polygon: ∫_P (n·ω) dω = ½ Σ_i Θ_i n·normalize(p_i ×
// p_{i+1}), Θ_i the angle between p_i and p_{i+1}, vertices counter-clockwise about ℓ (a towards b
// with (x, y = ℓ × x, ℓ) right-handed). Θ_i is atan(|p_i × p_{i+1}|, p_i·p_{i+1}) (acos of the
// normalized dot product, which loses half its digits for the short edges of small lights), and
// Θ_i n·normalize(c) = (Θ_i / |c|) n·c with Θ / |c| -> 1 / (|p_i| |p_{i+1}|) as an edge degenerates
// (no division by zero; such an edge adds nothing). n, ℓ unit; x need not be orthogonal to ℓ (it
// is projected off ℓ here: the light frame's axis as the ray tracer takes it). The point-light
// limit (t = 0, or x along ℓ): max(n·ℓ, 0). A line (a region one texel wide has no variance along
// that axis) is taken 1e-4 wide, as the ray tracer's estimate takes it (effect_environment.cpp).
MSM_FN float msm_rect_light_cosine(vec3 n, vec3 l, vec3 x_axis, vec2 t_in) {
  float n_dot_l = dot(n, l);
  vec3 x = x_axis - l * dot(x_axis, l);
  float x_length = length(x);
  if (!(max(t_in.x, t_in.y) > 0.0f && x_length > 1e-6f)) return max(n_dot_l, 0.0f);
  vec2 t = max(t_in, vec2(1e-4f));
  x /= x_length;
  vec3 y = cross(l, x);
  // The height of the point (a, b) of the rectangle's plane over the horizon: h = n·ℓ + a n·x + b n·y.
  float n_x = dot(n, x), n_y = dot(n, y);
  vec3 n_frame = vec3(n_x, n_y, n_dot_l);
  float reach = t.x * abs(n_x) + t.y * abs(n_y);
  if (n_dot_l >= reach) return n_dot_l; // every corner above the horizon
  if (n_dot_l <= -reach) return 0.0f;   // every corner below
  float facing = msm_rect_light_facing_integral(t);
  // Each edge's part above the horizon, then the horizon's chord from where the boundary leaves it
  // to where it comes back (a convex polygon crosses a line twice): the clipped polygon's edges in
  // order without storing it (an array written at a per-lane index is a scatter on a SIMD CPU).
  float sum = 0.0f;
  vec2 leaves = vec2(0.0f), comes_back = vec2(0.0f);
  for (int i = 0; i < 4; ++i) {
    vec2 p = msm_rect_corner(i, t), q = msm_rect_corner(i + 1, t);
    float hp = n_dot_l + p.x * n_x + p.y * n_y, hq = n_dot_l + q.x * n_x + q.y * n_y;
    bool p_above = hp >= 0.0f, q_above = hq >= 0.0f;
    vec2 crossing = p + (q - p) * (p_above != q_above ? hp / (hp - hq) : 0.0f);
    if (p_above && !q_above) leaves = crossing;
    if (!p_above && q_above) comes_back = crossing;
    vec2 a = p_above ? p : crossing, b = q_above ? q : crossing;
    if (p_above || q_above) sum += msm_lambert_edge(n_frame, a, b);
  }
  sum += msm_lambert_edge(n_frame, leaves, comes_back);
  return clamp(0.5f * sum / facing, 0.0f, max(n_dot_l + reach, 0.0f));
}

// The factor that replaces max(n·l, 0) for any directional light of the renderer: the rectangle's
// exact integral (msm_rect_light_cosine) where the light has half extents t (either > 0), else the
// disc's (msm_cone_cosine with its half-angle; 0: a point light, max(n·l, 0)). What the shading
// (shading.glsl, direct_light) and the energy tests evaluate.
MSM_FN float msm_light_cosine(vec3 n, vec3 l, vec3 x_axis, vec2 t, float cone_half_angle) {
  if (max(t.x, t.y) > 0.0f) return msm_rect_light_cosine(n, l, x_axis, t);
  return msm_cone_cosine(dot(n, l), cone_half_angle);
}

// The half extents (A, B) of a rectangle of tangents about the unit direction l, with orthonormal
// axes x and y, that holds the light (light_l, light_x, t, cone_half_angle) as msm_light_cosine
// integrates it: every direction of the light is along l + a x + b y with |a| <= A, |b| <= B. Its
// rectangle's corners (widened, on its x axis projected off light_l, as msm_rect_light_cosine takes
// them), a disc's circumscribed square, or the point light_l, each projected onto the plane
// through l (the light is convex there, so its corners bound it). (−1, −1) where some corner is
// not in front of l: no such rectangle.
MSM_FN vec2 msm_light_tangent_bounds(vec3 l, vec3 x, vec3 y, vec3 light_l, vec3 light_x, vec2 t_in,
                                     float cone_half_angle) {
  vec2 t = vec2(0.0f);
  vec3 lx = light_x - light_l * dot(light_x, light_l);
  if (max(t_in.x, t_in.y) > 0.0f) {
    if (length(lx) > 1e-6f) {
      t = max(t_in, vec2(1e-4f));
      lx = normalize(lx);
    }
  } else if (cone_half_angle > 0.0f) {
    if (!(cone_half_angle < 0.5f * MSM_PI)) return vec2(-1.0f);
    t = vec2(tan(cone_half_angle));
    lx = msm_perpendicular(light_l);
  }
  vec3 ly = cross(light_l, lx);
  vec2 bounds = vec2(0.0f);
  for (int i = 0; i < 4; ++i) {
    vec3 corner = light_l + ((i & 1) != 0 ? t.x : -t.x) * lx + ((i & 2) != 0 ? t.y : -t.y) * ly;
    float ahead = dot(corner, l);
    if (!(ahead > 1e-6f * length(corner))) return vec2(-1.0f);
    bounds = max(bounds, abs(vec2(dot(corner, x), dot(corner, y))) / ahead);
  }
  return bounds;
}

// Which side of the horizon of the unit normal n the rectangle of tangents (l, x, y, bounds: as
// msm_light_tangent_bounds makes it) is on: 1 where all of it is above (n·l − A |n·x| − B |n·y| >=
// 0: its corners' heights), −1 where all of it is below, 0 where it straddles the horizon or there
// are no bounds (bounds.x < 0).
MSM_FN int msm_tangent_rect_side(vec3 n, vec3 l, vec3 x, vec3 y, vec2 bounds) {
  if (bounds.x < 0.0f) return 0;
  float n_dot_l = dot(n, l);
  float reach = bounds.x * abs(dot(n, x)) + bounds.y * abs(dot(n, y));
  if (n_dot_l >= reach) return 1;
  if (n_dot_l <= -reach) return -1;
  return 0;
}

// Several lights' summed unshadowed irradiance Σ_k E_k msm_light_cosine_k(n) where each is wholly
// above the horizon of n: Σ_k E_k (n·l_k) = (Σ_k E_k l_kᵀ) n, linear in n. irradiance_by_direction
// is that sum of outer products (column j: Σ_k E_k l_k[j]); the shading's sub-lights take it
// wherever msm_tangent_rect_side says that all of them are above the horizon (shading.glsl).
MSM_FN vec3 msm_linear_irradiance(mat3 irradiance_by_direction, vec3 n) { return irradiance_by_direction * n; }

// Outgoing radiance factor of Eq. (18) for the rectangle: a diffuse surface of albedo ρ under the
// light reflects ρ / π · (irradiance on a facing surface) · msm_rect_light_cosine; that irradiance is
// L_e^A F with L_e^A = M_e / Ω (Eq. 16 over the rectangle), i.e. M_e F / Ω
// (msm_rect_light_facing_fraction). For the disc of the paper it is L_e^A π sin² α with Ω = 2π (1 −
// cos α): M_e (1 + cos α) / 2, Eq. (18)'s fraction; for a square and the disc of its solid angle the
// two differ by 3e-4 at 17° wide and 0.26% at 89°.
MSM_FN vec3 msm_area_light_facing_irradiance(MsmAreaLight light) {
  return light.irradiance * msm_rect_light_facing_fraction(light.half_extent);
}

MSM_END

#endif // MSM_LIGHT_PROBE_H
