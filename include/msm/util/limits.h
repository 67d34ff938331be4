// The limits of one `msm render` or `msm reference` (the same for both): the scene's total
// triangles and an estimate of the bytes the renderer or the ray tracer would allocate, checked
// before anything large is allocated so that absurd input ends in a message naming the limit and
// the value, not in std::bad_alloc after gigabytes (or the machine swapping).
//
// The defaults keep what works today on a 16-32 GB machine working: the heaviest render tried,
// `msm render --scene fence -t msm6-192 --shadow-size 8192`, takes
// 4.9 GB (lavapipe, where device memory is host memory) and is estimated at 4.9 GB; a 4096²
// reference is estimated at 1.6 GB. MSM_MAX_TRIANGLES and MSM_MAX_MEMORY_MB (environment) raise
// or lower them for a larger or smaller machine.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

namespace msm::limits {

// 32 M triangles: ~8 GB of ray tracer (kTracerBytesPerTriangle) or ~4 GB of renderer, within
// kMaxBytes; the largest built-in scene (models) has 28,674.
inline constexpr std::uint64_t kMaxTriangles = 32'000'000;
// 12 GiB: leaves 4 GB of a 16 GB machine to the system and the scene's own copy.
inline constexpr std::uint64_t kMaxBytes = 12ull << 30;

// The renderer per triangle: positions, normals, uvs (32 B per vertex; 1.5 vertices per triangle
// assumed, between a closed mesh's ~0.5 and a triangle soup's 3) and 12 B of indices, once in the
// staging copy and once on the device.
inline constexpr std::uint64_t kRendererBytesPerTriangle = 2 * (48 + 12);
// The ray tracer per triangle: Embree's BVH (an estimate of ~100 B per triangle at its default
// quality, not measured here) plus the tracer's own vertex, index and per-triangle data (~150 B).
inline constexpr std::uint64_t kTracerBytesPerTriangle = 256;
// Renderer per camera pixel: the colour, depth and shadow images on the device, their read-back
// (host) copies and the PNG/EXR encoders' buffers.
inline constexpr std::uint64_t kRendererBytesPerPixel = 64;
// Ray tracer per pixel: visibility (2 floats), visibility_rgb (3), radiance (3), surface (2), and
// the EXR writer's copy of each.
inline constexpr std::uint64_t kTracerBytesPerPixel = 96;
// Shadow-map depth: 32-bit depth per MSAA sample.
inline constexpr std::uint64_t kDepthBytesPerSample = 4;

// A limit exceeded: the message names the quantity, its value and the limit.
class LimitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The limit, or the environment's override (a positive integer; anything else is ignored).
inline std::uint64_t from_environment(const char* variable, std::uint64_t fallback, std::uint64_t unit = 1) {
  const char* text = std::getenv(variable);
  if (!text || !*text) return fallback;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (*end != '\0' || v == 0) return fallback;
  return std::uint64_t(v) * unit;
}
inline std::uint64_t max_triangles() { return from_environment("MSM_MAX_TRIANGLES", kMaxTriangles); }
inline std::uint64_t max_bytes() { return from_environment("MSM_MAX_MEMORY_MB", kMaxBytes, 1ull << 20); }

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
