// The spectral measures that judge blue-noise textures: a test helper of src/noise, compiled into
// its tests only (neither in the msm::blue_noise library nor installed).
#pragma once

#include "msm/noise/blue_noise.h"

#include <span>
#include <vector>

namespace msm::noise {

// Channel `channel` of texture `texture` as floats value / 255 in [0,1] (the input of
// measure_blue_noise). Throws std::out_of_range for a texture or channel that does not exist.
std::vector<float> blue_noise_channel(const BlueNoise& noise, int texture, int channel);

struct BlueNoiseMeasures {
  // Periodogram P(u,v) = |DFT(values - mean)|² / size² (white noise of variance s² has
  // E[P] = s²), at signed frequencies fu, fv in (-size/2, size/2], radius r = sqrt(fu² + fv²)
  // in cycles per tile.
  // Mean P over 0 < r <= size/8 divided by mean P over r >= size/4 (all bins out to the
  // corners). White noise: ~1. Blue noise: << 1.
  double low_to_high_power = 0;
  double low_band_power = 0;  // the numerator
  double high_band_power = 0; // the denominator
  // Coefficient of variation (standard deviation / mean) of the mean power in 8 angular sectors
  // of 22.5 degrees covering [0, 180) (P is symmetric: P(-f) = P(f)), within the annulus
  // size/4 <= r < size/2. 0 for a perfectly isotropic spectrum; an isotropic random texture
  // still shows ~1/sqrt(bins per sector) from the periodogram's own scatter (about 0.08 at size
  // 64, 0.04 at 128), so compare textures of the same size.
  double radial_anisotropy = 0;
  // With n = size²: true when round(v (n-1)) is a permutation of 0..n-1 (a rank array scaled to
  // [0,1]), or when 256 divides n and every 8-bit value round(255 v) occurs exactly n/256 times
  // (an 8-bit dither texture).
  bool ranks_unique = false;
  // Squared differences of the neighbour pairs that cross the wrap (from column size-1 to 0 or
  // row size-1 to 0) at the lags (1,0), (0,1), (1,1), (1,-1) (6 size - 2 pairs), divided by what
  // the interior pairs at the same lags predict (their mean per lag times the crossing count).
  // ~1 when the texture tiles without a seam (scatter about ±0.06 for one 64² texture). Blue
  // noise that does not tile scores ~0.85: across its wrap, neighbours are uncorrelated instead
  // of anti-correlated. A seam also leaks power into the low band along the axes, which
  // low_to_high_power shows (about 50-fold for such a crop).
  double tiling_seam = 0;
  // Mean and variance of the values.
  double mean = 0;
  double variance = 0;
};

// The measures of one channel of one texture, values in [0,1] row-major.
// Preconditions (std::invalid_argument otherwise): 8 <= size <= 1024, values.size() == size²,
// every value finite. Cost: a direct separable DFT, O(size³) (1 ms at 64, 10 ms at 128).
BlueNoiseMeasures measure_blue_noise(std::span<const float> values, int size);

} // namespace msm::noise
