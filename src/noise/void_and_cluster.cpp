// Blue noise by void-and-cluster (Ulichney 1993): the generator, compiled once into both
// msm::blue_noise and the build tool that embeds the renderer's set (embed_blue_noise.cpp).
#include "msm/noise/blue_noise.h"
#include "msm/util/random.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>

namespace msm::noise {
namespace {

using util::mix64;
using util::SplitMix64;

// The seed of run `index` (texture t, channel c: index t * channels + c) of a set.
std::uint64_t derived_seed(std::uint64_t seed, std::uint64_t index) {
  return mix64(seed ^ mix64(index + 0x632be59bd9b4e019ull));
}

void require_sigma(double sigma) {
  if (!std::isfinite(sigma) || !(sigma > 0.0))
    throw std::invalid_argument(fmt::format("blue noise: sigma must be finite and > 0, got {}", sigma));
}

// ---- Void and cluster ------------------------------------------------------------------------

// The energy of a binary pattern on the torus: E(p) = sum over set pixels q of g(wrapped |p - q|),
// kept incrementally. The kernel is tabulated over K x K offsets off0 .. off0 + K - 1 (K = size
// when the truncated kernel would not fit, so that every residue appears once).
class EnergyField {
 public:
  EnergyField(int size, double sigma) : n_(size), energy_(std::size_t(size) * std::size_t(size), 0.0f) {
    // exp(-r² / 2σ²) < 1e-9 for r > σ sqrt(2 ln 1e9).
    const int radius = int(std::ceil(sigma * std::sqrt(2.0 * std::log(1e9))));
    if (2 * radius + 1 >= size) {
      k_ = size;
      off0_ = 0;
    } else {
      k_ = 2 * radius + 1;
      off0_ = -radius;
    }
    std::vector<double> g(static_cast<std::size_t>(k_));
    for (int a = 0; a < k_; ++a) {
      const int residue = ((off0_ + a) % size + size) % size;
      const int d = std::min(residue, size - residue); // wrap-around distance along one axis
      g[std::size_t(a)] = double(d) * double(d);
    }
    lut_.resize(std::size_t(k_) * std::size_t(k_));
    for (int a = 0; a < k_; ++a)
      for (int b = 0; b < k_; ++b)
        lut_[std::size_t(a) * std::size_t(k_) + std::size_t(b)] =
            float(std::exp(-(g[std::size_t(a)] + g[std::size_t(b)]) / (2.0 * sigma * sigma)));
  }

  std::span<const float> energy() const { return energy_; }
  void clear() { std::fill(energy_.begin(), energy_.end(), 0.0f); }

  // Adds or removes the kernel centred on pixel p.
  void splat(int p, bool add) {
    const int py = p / n_, px = p % n_;
    const int start = ((px + off0_) % n_ + n_) % n_;
    const int len1 = std::min(k_, n_ - start);
    for (int a = 0; a < k_; ++a) {
      const int y = ((py + off0_ + a) % n_ + n_) % n_;
      float* row = energy_.data() + std::size_t(y) * std::size_t(n_);
      const float* lut = lut_.data() + std::size_t(a) * std::size_t(k_);
      if (add) {
        for (int b = 0; b < len1; ++b) row[start + b] += lut[b];
        for (int b = len1; b < k_; ++b) row[b - len1] += lut[b];
      } else {
        for (int b = 0; b < len1; ++b) row[start + b] -= lut[b];
        for (int b = len1; b < k_; ++b) row[b - len1] -= lut[b];
      }
    }
  }

 private:
  int n_;
  int k_ = 0, off0_ = 0;
  std::vector<float> lut_;
  std::vector<float> energy_;
};

// Highest (want_max) or lowest energy among pixels with set[i] == which; ties: lowest index.
// Two passes (a branch-free reduction, then the first index with that value) so that the first
// vectorizes.
int extreme(std::span<const float> energy, const std::vector<std::uint8_t>& set, std::uint8_t which, bool want_max) {
  const std::size_t n = energy.size();
  const float inf = std::numeric_limits<float>::infinity();
  float best = want_max ? -inf : inf;
  if (want_max) {
    for (std::size_t i = 0; i < n; ++i) best = std::max(best, set[i] == which ? energy[i] : -inf);
  } else {
    for (std::size_t i = 0; i < n; ++i) best = std::min(best, set[i] == which ? energy[i] : inf);
  }
  for (std::size_t i = 0; i < n; ++i)
    if (set[i] == which && energy[i] == best) return int(i);
  throw std::logic_error("void and cluster: no candidate pixel"); // unreachable: callers ensure one
}

} // namespace

std::vector<std::uint32_t> void_and_cluster_ranks(int size, double sigma, std::uint64_t seed) {
  if (size < 2 || size > 1024)
    throw std::invalid_argument(fmt::format("void_and_cluster_ranks: size must be in [2, 1024], got {}", size));
  require_sigma(sigma);
  const int n = size * size;
  std::vector<std::uint32_t> rank(std::size_t(n), 0);
  EnergyField field(size, sigma);
  std::vector<std::uint8_t> on(std::size_t(n), 0);

  // Initial binary pattern: m random minority pixels (a partial Fisher-Yates shuffle) ...
  const int m = std::max(1, n / 10);
  {
    SplitMix64 rng(seed);
    std::vector<int> order(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) order[std::size_t(i)] = i;
    for (int i = 0; i < m; ++i) {
      const int j = i + int(rng.below(std::uint64_t(n - i)));
      std::swap(order[std::size_t(i)], order[std::size_t(j)]);
      on[std::size_t(order[std::size_t(i)])] = 1;
      field.splat(order[std::size_t(i)], true);
    }
  }
  // ... then the tightest cluster moves to the largest void until it stays where it is (the
  // bound only guards against a cycle among exactly tied energies; it is never reached in practice).
  for (long iteration = 0; iteration < 64L * n; ++iteration) {
    const int cluster = extreme(field.energy(), on, 1, true);
    on[std::size_t(cluster)] = 0;
    field.splat(cluster, false);
    const int largest_void = extreme(field.energy(), on, 0, false);
    on[std::size_t(largest_void)] = 1;
    field.splat(largest_void, true);
    if (largest_void == cluster) break;
  }
  const std::vector<std::uint8_t> prototype = on;

  // Phase 1: remove the tightest clusters; ranks m-1 .. 0.
  for (int r = m - 1; r >= 0; --r) {
    const int cluster = extreme(field.energy(), on, 1, true);
    on[std::size_t(cluster)] = 0;
    field.splat(cluster, false);
    rank[std::size_t(cluster)] = std::uint32_t(r);
  }
  // Phase 2: from the prototype, fill the largest voids up to half; ranks m .. n/2 - 1.
  // (Energies recomputed from scratch: no rounding drift carried over from phase 1.)
  on = prototype;
  field.clear();
  for (int i = 0; i < n; ++i)
    if (on[std::size_t(i)]) field.splat(i, true);
  const int half = n / 2;
  int r = m;
  for (; r < half; ++r) {
    const int largest_void = extreme(field.energy(), on, 0, false);
    on[std::size_t(largest_void)] = 1;
    field.splat(largest_void, true);
    rank[std::size_t(largest_void)] = std::uint32_t(r);
  }
  // Phase 3: the empty pixels are now the minority: energy of the empty pixels, and the
  // tightest cluster of empty pixels is filled; ranks n/2 .. n-1.
  field.clear();
  for (int i = 0; i < n; ++i)
    if (!on[std::size_t(i)]) field.splat(i, true);
  for (; r < n; ++r) {
    const int cluster = extreme(field.energy(), on, 0, true);
    on[std::size_t(cluster)] = 1;
    field.splat(cluster, false);
    rank[std::size_t(cluster)] = std::uint32_t(r);
  }
  return rank;
}

namespace {

void require_set(int size, int count, int channels, double sigma) {
  if (size < 16 || size > 1024 || size % 16 != 0)
    throw std::invalid_argument(
        fmt::format("generate_blue_noise: size must be a multiple of 16 in [16, 1024], got {}", size));
  if (count < 1 || count > 4096)
    throw std::invalid_argument(fmt::format("generate_blue_noise: count must be in [1, 4096], got {}", count));
  if (channels < 1 || channels > 4)
    throw std::invalid_argument(fmt::format("generate_blue_noise: channels must be in [1, 4], got {}", channels));
  require_sigma(sigma);
}

} // namespace

BlueNoise generate_blue_noise(int size, int count, int channels, double sigma, std::uint64_t seed) {
  require_set(size, count, channels, sigma);
  BlueNoise noise{size, count, channels, {}};
  const std::size_t pixels = std::size_t(size) * std::size_t(size);
  noise.texels.resize(pixels * std::size_t(count) * std::size_t(channels));
  const int runs = count * channels;
  // Runs write disjoint texels and each is sequential inside: the set is the same for any thread count.
  tbb::parallel_for(tbb::blocked_range<int>(0, runs, 1), [&](const tbb::blocked_range<int>& range) {
    for (int run = range.begin(); run != range.end(); ++run) {
      const std::vector<std::uint32_t> rank =
          void_and_cluster_ranks(size, sigma, derived_seed(seed, std::uint64_t(run)));
      const int texture = run / channels, channel = run % channels;
      std::uint8_t* out = noise.texels.data() + std::size_t(texture) * pixels * std::size_t(channels);
      for (std::size_t i = 0; i < pixels; ++i)
        out[i * std::size_t(channels) + std::size_t(channel)] = std::uint8_t(std::uint64_t(rank[i]) * 256 / pixels);
    }
  });
  return noise;
}

} // namespace msm::noise
