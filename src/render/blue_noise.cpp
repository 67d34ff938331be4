// Blue noise by void-and-cluster (Ulichney 1993), its cache file and its spectral measures.
#include "msm/render/blue_noise.h"
#include "msm/util/random.h"

#include "msm/image/image.h"
#include "msm/image/io.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <system_error>

namespace msm::render {
namespace {

namespace fs = std::filesystem;

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
    const int void_ = extreme(field.energy(), on, 0, false);
    on[std::size_t(void_)] = 1;
    field.splat(void_, true);
    if (void_ == cluster) break;
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
    const int void_ = extreme(field.energy(), on, 0, false);
    on[std::size_t(void_)] = 1;
    field.splat(void_, true);
    rank[std::size_t(void_)] = std::uint32_t(r);
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
  // Isolated: a thread waiting here must not pick up an unrelated outer task that could call
  // blue_noise() again while its first call is still initializing the set.
  tbb::this_task_arena::isolate([&] {
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
  });
  return noise;
}

std::vector<float> blue_noise_channel(const BlueNoise& noise, int texture, int channel) {
  if (texture < 0 || texture >= noise.count || channel < 0 || channel >= noise.channels)
    throw std::out_of_range(fmt::format("blue_noise_channel: texture {} channel {} of a set of {} x {} channels",
                                        texture, channel, noise.count, noise.channels));
  const std::size_t pixels = std::size_t(noise.size) * std::size_t(noise.size);
  const std::size_t stride = std::size_t(noise.channels);
  const std::uint8_t* in = noise.texels.data() + std::size_t(texture) * pixels * stride + std::size_t(channel);
  std::vector<float> values(pixels);
  for (std::size_t i = 0; i < pixels; ++i) values[i] = float(in[i * stride]) / 255.0f;
  return values;
}

// ---- Cache -------------------------------------------------------------------------------------

namespace {

constexpr char cache_magic[8] = {'M', 'S', 'M', 'B', 'L', 'U', 'E', 'N'};
constexpr std::size_t cache_header_bytes = 8 + 4 * 4 + 8 + 8 + 8;
constexpr std::size_t cache_trailer_bytes = 8;

std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::uint8_t b : bytes) {
    h ^= b;
    h *= 0x100000001b3ull;
  }
  return h;
}

void put(std::vector<std::uint8_t>& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(std::uint8_t(value >> (8 * i))); // little-endian
}

std::uint64_t get(std::span<const std::uint8_t> in, std::size_t at, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value |= std::uint64_t(in[at + std::size_t(i)]) << (8 * i);
  return value;
}

std::vector<std::uint8_t> cache_header(const BlueNoiseParams& p, std::size_t payload) {
  std::vector<std::uint8_t> out(std::begin(cache_magic), std::end(cache_magic));
  put(out, blue_noise_cache_version, 4);
  put(out, std::uint32_t(p.size), 4);
  put(out, std::uint32_t(p.count), 4);
  put(out, std::uint32_t(p.channels), 4);
  put(out, std::bit_cast<std::uint64_t>(p.sigma), 8);
  put(out, p.seed, 8);
  put(out, payload, 8);
  return out;
}

std::vector<std::uint8_t> serialize(const BlueNoiseParams& p, const BlueNoise& noise) {
  std::vector<std::uint8_t> out = cache_header(p, noise.texels.size());
  out.insert(out.end(), noise.texels.begin(), noise.texels.end());
  put(out, fnv1a64(out), 8);
  return out;
}

std::size_t payload_bytes(const BlueNoiseParams& p) {
  return std::size_t(p.size) * std::size_t(p.size) * std::size_t(p.count) * std::size_t(p.channels);
}

// The set in the file when the file is exactly the one these parameters write; nullopt otherwise.
std::optional<BlueNoise> read_cache(const fs::path& file, const BlueNoiseParams& p) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  const std::size_t payload = payload_bytes(p);
  if (bytes.size() != cache_header_bytes + payload + cache_trailer_bytes) return std::nullopt;
  const std::vector<std::uint8_t> header = cache_header(p, payload);
  if (!std::equal(header.begin(), header.end(), bytes.begin())) return std::nullopt; // magic, version, parameters
  const std::span<const std::uint8_t> all(bytes);
  if (get(all, cache_header_bytes + payload, 8) != fnv1a64(all.first(cache_header_bytes + payload)))
    return std::nullopt;
  BlueNoise noise{p.size, p.count, p.channels, {}};
  noise.texels.assign(bytes.begin() + std::ptrdiff_t(cache_header_bytes),
                      bytes.begin() + std::ptrdiff_t(cache_header_bytes + payload));
  return noise;
}

std::optional<fs::path> env_path(const char* name) {
  const char* value = std::getenv(name);
  if (value == nullptr || *value == '\0') return std::nullopt;
  return fs::path(value);
}

} // namespace

std::optional<fs::path> blue_noise_cache_dir() {
  if (auto dir = env_path("MSM_CACHE_DIR")) return dir;
  if (auto dir = env_path("XDG_CACHE_HOME")) return *dir / "msm";
  if (auto dir = env_path("HOME")) return *dir / ".cache" / "msm";
  return std::nullopt;
}

fs::path blue_noise_cache_file_name(const BlueNoiseParams& p) {
  return fmt::format("blue_noise-v{}-{}x{}-n{}-c{}-sigma{:.3f}-seed{:016x}.bin", blue_noise_cache_version, p.size,
                     p.size, p.count, p.channels, p.sigma, p.seed);
}

CachedBlueNoise load_or_generate_blue_noise(const BlueNoiseParams& p, const std::optional<fs::path>& cache_dir) {
  require_set(p.size, p.count, p.channels, p.sigma);
  CachedBlueNoise result;
  if (cache_dir) {
    result.file = *cache_dir / blue_noise_cache_file_name(p);
    std::error_code ec;
    if (fs::exists(result.file, ec)) {
      if (std::optional<BlueNoise> cached = read_cache(result.file, p)) {
        result.noise = std::move(*cached);
        result.source = BlueNoiseSource::loaded;
        return result;
      }
      result.rejected_file = true;
    }
  }
  result.noise = generate_blue_noise(p.size, p.count, p.channels, p.sigma, p.seed);
  result.source = BlueNoiseSource::generated_only;
  if (cache_dir) {
    std::error_code ec;
    fs::create_directories(*cache_dir, ec);
    if (!ec) {
      try {
        msm::image::write_file_atomic(result.file, serialize(p, result.noise));
        result.source = BlueNoiseSource::generated;
      } catch (const std::exception&) {
        // Not writable: keep the set in memory only.
      }
    }
  }
  return result;
}

const BlueNoise& blue_noise() {
  static const BlueNoise noise = load_or_generate_blue_noise(BlueNoiseParams{}, blue_noise_cache_dir()).noise;
  return noise;
}

// ---- Measures ----------------------------------------------------------------------------------

BlueNoiseMeasures measure_blue_noise(std::span<const float> values, int size) {
  if (size < 8 || size > 1024)
    throw std::invalid_argument(fmt::format("measure_blue_noise: size must be in [8, 1024], got {}", size));
  const std::size_t n = std::size_t(size) * std::size_t(size);
  if (values.size() != n)
    throw std::invalid_argument(
        fmt::format("measure_blue_noise: {} values for a {}x{} texture", values.size(), size, size));
  for (float v : values)
    if (!std::isfinite(v)) throw std::invalid_argument("measure_blue_noise: non-finite value");

  BlueNoiseMeasures m;
  double sum = 0;
  for (float v : values) sum += v;
  m.mean = sum / double(n);
  double var = 0;
  for (float v : values) var += (v - m.mean) * (v - m.mean);
  m.variance = var / double(n);

  // Periodogram by a separable direct DFT: rows, then columns.
  using cd = std::complex<double>;
  std::vector<cd> twiddle(static_cast<std::size_t>(size));
  for (int k = 0; k < size; ++k) {
    const double angle = -2.0 * std::numbers::pi * double(k) / double(size);
    twiddle[std::size_t(k)] = cd(std::cos(angle), std::sin(angle));
  }
  const auto at = [size](int x, int y) { return std::size_t(y) * std::size_t(size) + std::size_t(x); };
  std::vector<cd> rows(n), spectrum(n);
  for (int y = 0; y < size; ++y)
    for (int u = 0; u < size; ++u) {
      cd acc = 0;
      for (int x = 0; x < size; ++x) acc += (double(values[at(x, y)]) - m.mean) * twiddle[std::size_t((u * x) % size)];
      rows[at(u, y)] = acc;
    }
  for (int u = 0; u < size; ++u)
    for (int v = 0; v < size; ++v) {
      cd acc = 0;
      for (int y = 0; y < size; ++y) acc += rows[at(u, y)] * twiddle[std::size_t((v * y) % size)];
      spectrum[at(u, v)] = acc;
    }

  constexpr int sectors = 8;
  std::array<double, sectors> sector_sum{}, sector_count{};
  double low = 0, high = 0;
  long low_n = 0, high_n = 0;
  const double low_r = size / 8.0, high_r = size / 4.0, nyquist = size / 2.0;
  for (int v = 0; v < size; ++v)
    for (int u = 0; u < size; ++u) {
      if (u == 0 && v == 0) continue;
      const int fu = u <= size / 2 ? u : u - size;
      const int fv = v <= size / 2 ? v : v - size;
      const double r = std::hypot(double(fu), double(fv));
      const double power = std::norm(spectrum[at(u, v)]) / double(n);
      if (r <= low_r) {
        low += power;
        ++low_n;
      }
      if (r >= high_r) {
        high += power;
        ++high_n;
        if (r < nyquist) {
          double angle = std::atan2(double(fv), double(fu)); // (-pi, pi]
          if (angle < 0) angle += std::numbers::pi;
          if (angle >= std::numbers::pi) angle -= std::numbers::pi;
          const int s = std::min(sectors - 1, int(angle / (std::numbers::pi / sectors)));
          sector_sum[std::size_t(s)] += power;
          sector_count[std::size_t(s)] += 1;
        }
      }
    }
  m.low_band_power = low / double(low_n);
  m.high_band_power = high / double(high_n);
  m.low_to_high_power =
      m.high_band_power > 0 ? m.low_band_power / m.high_band_power : std::numeric_limits<double>::infinity();
  double sector_mean = 0;
  std::array<double, sectors> sector_power{};
  for (int s = 0; s < sectors; ++s) {
    sector_power[std::size_t(s)] = sector_sum[std::size_t(s)] / std::max(1.0, sector_count[std::size_t(s)]);
    sector_mean += sector_power[std::size_t(s)] / sectors;
  }
  double sector_var = 0;
  for (double p : sector_power) sector_var += (p - sector_mean) * (p - sector_mean) / sectors;
  m.radial_anisotropy = sector_mean > 0 ? std::sqrt(sector_var) / sector_mean : std::numeric_limits<double>::infinity();

  // Ranks: a permutation of 0..n-1, or a flat 8-bit histogram.
  {
    std::vector<std::uint32_t> seen(n, 0);
    bool permutation = true;
    for (float v : values) {
      const double scaled = std::round(double(v) * double(n - 1));
      if (scaled < 0 || scaled > double(n - 1) || seen[std::size_t(scaled)]++ != 0) {
        permutation = false;
        break;
      }
    }
    bool flat = n % 256 == 0;
    if (flat) {
      std::array<std::size_t, 256> histogram{};
      for (float v : values) {
        const double q = std::round(double(v) * 255.0);
        if (q < 0 || q > 255) {
          flat = false;
          break;
        }
        ++histogram[std::size_t(q)];
      }
      for (std::size_t h : histogram) flat = flat && h == n / 256;
    }
    m.ranks_unique = permutation || flat;
  }

  // Tiling seam: squared neighbour differences of the pairs that cross the wrap against what the
  // interior pairs at the same lag predict, over the lags (1,0), (0,1), (1,1), (1,-1).
  constexpr std::array<std::array<int, 2>, 4> lags{{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  double seam = 0, predicted = 0;
  for (const auto& [lx, ly] : lags) {
    double cross = 0, inside = 0;
    long cross_n = 0, inside_n = 0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const int x2 = x + lx, y2 = y + ly;
        const double d = double(values[at(x, y)]) - double(values[at((x2 + size) % size, (y2 + size) % size)]);
        if (x2 >= size || y2 >= size || y2 < 0) {
          cross += d * d;
          ++cross_n;
        } else {
          inside += d * d;
          ++inside_n;
        }
      }
    seam += cross;
    predicted += double(cross_n) * inside / double(inside_n);
  }
  m.tiling_seam = predicted > 0 ? seam / predicted : (seam > 0 ? std::numeric_limits<double>::infinity() : 1.0);
  return m;
}

} // namespace msm::render
