// The one random-number generator of msm's C++ code (C++ only: include/msm/util holds host
// utilities without GPU or GLSL code): SplitMix64 (Steele, Lea, Flood 2014), small, fast,
// statistically fine for sampling and shuffling, and identical on every platform, so that the
// ray tracer's images and the blue-noise textures do not depend on the machine or thread count.
#pragma once

#include <cstdint>

namespace msm::util {

// The SplitMix64 output function (a 64-bit finalizer: also a good hash of a counter).
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

class SplitMix64 {
 public:
  explicit constexpr SplitMix64(std::uint64_t seed) : state_(seed) {}
  constexpr std::uint64_t next() { return mix64(state_ += 0x9e3779b97f4a7c15ull); }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  // Uniform in [0, bound) without modulo bias. Precondition: bound > 0.
  std::uint64_t below(std::uint64_t bound) {
    const std::uint64_t threshold = (0 - bound) % bound; // 2^64 mod bound
    for (;;) {
      const std::uint64_t r = next();
      if (r >= threshold) return r % bound;
    }
  }

 private:
  std::uint64_t state_;
};

} // namespace msm::util
