// The limits of one `msm render` or `msm reference` (the same for both): the scene's total
// triangles and an estimate of the bytes the renderer or the ray tracer would allocate, checked
// before anything large is allocated so that absurd input ends in a message naming the limit and
// the value, not in std::bad_alloc after gigabytes (or the machine swapping).
//
// The defaults keep what works today on a 16-32 GB machine working: the heaviest render tried,
// `msm render --scene fence -t msm6-192 --shadow-size 8192`, takes 4.9 GB (lavapipe, where device
// memory is host memory) and is estimated at 4.9 GB; a 16384² hard reference is estimated at
// 10.0 GiB (allowed), a 16384² translucent one at 13.0 GiB (refused). MSM_MAX_TRIANGLES and
// MSM_MAX_MEMORY_MB (environment) raise or lower them for a larger or smaller machine.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

namespace msm::limits {

// 32 M triangles: ~8 GB of renderer or ray tracer (k*BytesPerTriangle), within kMaxBytes; the
// largest built-in scene (models) has 28,674.
inline constexpr std::uint64_t kMaxTriangles = 32'000'000;
// 12 GiB: leaves 4 GB of a 16 GB machine to the system and the scene's own copy.
inline constexpr std::uint64_t kMaxBytes = 12ull << 30;

// The renderer per triangle, process and device together: measured 193 B (lavapipe, a
// 4,000,000-triangle plane of 0.5 vertices per triangle, resident set over a 14-triangle scene:
// the scene, its staging and device copies); meshes with more vertices per triangle (up to 3 for
// a soup of 32-B vertices) need more, hence the headroom.
inline constexpr std::uint64_t kRendererBytesPerTriangle = 256;
// The ray tracer per triangle: measured 141 B in the same way (the scene, Embree's BVH at its
// default quality, the tracer's own vertex, index and per-triangle data); headroom as above.
inline constexpr std::uint64_t kTracerBytesPerTriangle = 256;
// Renderer per camera pixel: measured 72 B (lavapipe, pcf at 4096², resident set over 16²: the
// colour, depth and shadow images, their read-back copies, the PNG/EXR encoders), with headroom.
inline constexpr std::uint64_t kRendererBytesPerPixel = 96;
// Ray tracer per pixel: the images as floats (visibility 2, radiance 3, surface 2; translucent adds
// visibility_rgb 3) and the EXR encoder's copy of the largest (3 floats): 40 B, 52 B translucent.
// Measured: 28 B for hard at 4096² (the encoded files are compressed).
inline constexpr std::uint64_t kTracerBytesPerPixel = 40;
inline constexpr std::uint64_t kTracerBytesPerPixelTranslucent = 52;
// scattering: visibility 4, radiance 3, surface 2, scattering 4 floats, and the encoder's copy of 4.
inline constexpr std::uint64_t kTracerBytesPerPixelScattering = 68;
// Shadow-map depth: 32-bit depth per MSAA sample.
inline constexpr std::uint64_t kDepthBytesPerSample = 4;

// A limit exceeded: the message names the quantity, its value and the limit.
class LimitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The limit, or the environment's override: a positive whole number (of `unit`s), digits only.
// Anything else (empty counts as unset) is a LimitError naming the variable and the value, not a
// silent fallback: "-5" would otherwise wrap to 2^64 - 5, and "0" or "abc" quietly mean the default.
inline std::uint64_t from_environment(const char* variable, std::uint64_t fallback, std::uint64_t unit = 1) {
  const char* text = std::getenv(variable);
  if (!text || !*text) return fallback;
  std::uint64_t v = 0;
  bool valid = true;
  for (const char* c = text; *c && valid; ++c) {
    const unsigned digit = unsigned(*c) - unsigned('0');
    valid = digit <= 9 && v <= (UINT64_MAX - digit) / 10;
    v = valid ? v * 10 + digit : v;
  }
  if (!valid || v == 0 || v > UINT64_MAX / unit) {
    std::string shown(text);
    if (shown.size() > 40) shown = shown.substr(0, 40) + "...";
    throw LimitError(fmt::format("{}={}: expected a whole number from 1 to {} (unset it for the default)", variable,
                                 shown, UINT64_MAX / unit));
  }
  return v * unit;
}
inline std::uint64_t max_triangles() { return from_environment("MSM_MAX_TRIANGLES", kMaxTriangles); }
inline std::uint64_t max_bytes() { return from_environment("MSM_MAX_MEMORY_MB", kMaxBytes, 1ull << 20); }

// The environment's overrides of limits (the import timeout's default is the scene library's;
// any positive value stands in for it here): LimitError for the first malformed one, so that a
// command refuses a mistyped override before any work rather than when (or if) it reads it.
inline void check_environment() {
  from_environment("MSM_MAX_TRIANGLES", kMaxTriangles);
  from_environment("MSM_MAX_MEMORY_MB", kMaxBytes, 1ull << 20);
  from_environment("MSM_IMPORT_TIMEOUT_S", 1);
}

// The bytes of a light's shadow maps: `layers` (one per light) of size² texels, each with the
// MSAA depth samples and `sets` moment images (one per colour channel) of moment_bytes per texel,
// each resolved and blurred through a temporary (two copies) plus its mip chain (a third more).
inline std::uint64_t shadow_map_bytes(std::uint64_t size, std::uint64_t layers, std::uint64_t msaa,
                                      std::uint64_t moment_bytes, bool mipmaps, std::uint64_t sets = 1) {
  const std::uint64_t texels = size * size * layers;
  const std::uint64_t moments = moment_bytes * sets * (mipmaps ? 7 : 6) / 3; // (2 + 1/3) or 2 copies
  return texels * (msaa * kDepthBytesPerSample + moments);
}

inline std::string with_commas(std::uint64_t v) {
  std::string digits = std::to_string(v), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

// LimitError when the scene has more triangles than max_triangles().
inline void check_triangles(std::uint64_t triangles) {
  const std::uint64_t limit = max_triangles();
  if (triangles > limit)
    throw LimitError(fmt::format("the scene has {} triangles; the limit is {} (MSM_MAX_TRIANGLES raises it)",
                                 with_commas(triangles), with_commas(limit)));
}

// LimitError when `what` (e.g. "msm6-192 at 8192² shadow map") would need more than max_bytes().
inline void check_bytes(const std::string& what, std::uint64_t bytes) {
  const std::uint64_t limit = max_bytes();
  if (bytes > limit)
    throw LimitError(fmt::format("{} needs about {:.1f} GiB; the limit is {:.1f} GiB (MSM_MAX_MEMORY_MB raises it)",
                                 what, double(bytes) / double(1ull << 30), double(limit) / double(1ull << 30)));
}

} // namespace msm::limits
