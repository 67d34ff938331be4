// The spectral measures of blue-noise textures (test helper; see blue_noise_measures.h).
#include "blue_noise_measures.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace msm::noise {

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

namespace {

using Complex = std::complex<double>;

std::size_t texel_index(int size, int x, int y) { return std::size_t(y) * std::size_t(size) + std::size_t(x); }

// The DFT of values - mean by a separable direct transform: rows, then columns.
std::vector<Complex> spectrum_of(std::span<const float> values, int size, double mean) {
  std::vector<Complex> twiddle(static_cast<std::size_t>(size));
  for (int k = 0; k < size; ++k) {
    const double angle = -2.0 * std::numbers::pi * double(k) / double(size);
    twiddle[std::size_t(k)] = Complex(std::cos(angle), std::sin(angle));
  }
  const auto at = [size](int x, int y) { return texel_index(size, x, y); };
  std::vector<Complex> rows(values.size()), spectrum(values.size());
  for (int y = 0; y < size; ++y)
    for (int u = 0; u < size; ++u) {
      Complex acc = 0;
      for (int x = 0; x < size; ++x) acc += (double(values[at(x, y)]) - mean) * twiddle[std::size_t((u * x) % size)];
      rows[at(u, y)] = acc;
    }
  for (int u = 0; u < size; ++u)
    for (int v = 0; v < size; ++v) {
      Complex acc = 0;
      for (int y = 0; y < size; ++y) acc += rows[at(u, y)] * twiddle[std::size_t((v * y) % size)];
      spectrum[at(u, v)] = acc;
    }
  return spectrum;
}

// The low and high bands' mean power and the anisotropy of the high band's 8 angular sectors
// (BlueNoiseMeasures), from the spectrum.
void measure_bands(const std::vector<Complex>& spectrum, int size, BlueNoiseMeasures& m) {
  constexpr int sectors = 8;
  std::array<double, sectors> sector_sum{}, sector_count{};
  double low = 0, high = 0;
  long low_n = 0, high_n = 0;
  const double low_r = size / 8.0, high_r = size / 4.0, nyquist = size / 2.0;
  const double n = double(spectrum.size());
  for (int v = 0; v < size; ++v)
    for (int u = 0; u < size; ++u) {
      if (u == 0 && v == 0) continue;
      const int fu = u <= size / 2 ? u : u - size;
      const int fv = v <= size / 2 ? v : v - size;
      const double r = std::hypot(double(fu), double(fv));
      const double power = std::norm(spectrum[texel_index(size, u, v)]) / n;
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
}

// Ranks: a permutation of 0..n-1, or a flat 8-bit histogram (BlueNoiseMeasures::ranks_unique).
bool ranks_unique(std::span<const float> values) {
  const std::size_t n = values.size();
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
  return permutation || flat;
}

// Tiling seam: squared neighbour differences of the pairs that cross the wrap against what the
// interior pairs at the same lag predict, over the lags (1,0), (0,1), (1,1), (1,-1).
double tiling_seam(std::span<const float> values, int size) {
  const auto at = [size](int x, int y) { return texel_index(size, x, y); };
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
  return predicted > 0 ? seam / predicted : (seam > 0 ? std::numeric_limits<double>::infinity() : 1.0);
}

} // namespace

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
  measure_bands(spectrum_of(values, size, m.mean), size, m);
  m.ranks_unique = ranks_unique(values);
  m.tiling_seam = tiling_seam(values, size);
  return m;
}

} // namespace msm::noise
