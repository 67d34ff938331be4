// Fragments, kernels, receiver depths and PCF of a depth-peeled stack (stack.h).
#include "msm/evaluate/stack.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "msm/filter.h"

namespace msm::evaluate {

void validate(const StackSettings& s) {
  if (s.size < 1 || s.size > reference::kMaxLayerMapSize)
    throw std::invalid_argument(
        fmt::format("shadow map size {} is outside [1, {}]", s.size, reference::kMaxLayerMapSize));
  if (s.grid < 2 || s.grid > kMaxGridPoints)
    throw std::invalid_argument(fmt::format("depth grid of {} points is outside [2, {}]", s.grid, kMaxGridPoints));
  if (!msm_filter_valid(s.filter_taps, s.filter_sigma))
    throw std::invalid_argument(fmt::format("filter of {} taps with sigma {} is invalid (odd taps in [1, {}], sigma in "
                                            "[{}, {}])",
                                            s.filter_taps, s.filter_sigma, MSM_FILTER_MAX_TAPS, MSM_FILTER_MIN_SIGMA,
                                            MSM_FILTER_MAX_SIGMA));
  if (s.max_layers < 1 || s.max_layers > reference::kMaxLayers)
    throw std::invalid_argument(fmt::format("max layers {} is outside [1, {}]", s.max_layers, reference::kMaxLayers));
  if (!(s.max_bias >= 0.0 && s.max_bias <= 1.0))
    throw std::invalid_argument(fmt::format("max bias {} is outside [0, 1]", s.max_bias));
  if (s.threads < 0 || s.threads > 1024)
    throw std::invalid_argument(fmt::format("threads {} is outside [0, 1024]", s.threads));
}

std::vector<double> kernel_weights(int taps, float sigma) {
  const auto count = static_cast<std::size_t>(taps);
  std::vector<double> w1(count), w2(count * count);
  double sum = 0.0;
  for (int k = 0; k < taps; ++k) sum += w1[k] = double(msm_gaussian_weight(k, taps, sigma));
  for (int j = 0; j < taps; ++j)
    for (int k = 0; k < taps; ++k) w2[std::size_t(j) * taps + k] = (w1[j] / sum) * (w1[k] / sum);
  return w2;
}

Stack make_stack(std::string name, const reference::ShadowLayers& layers, const StackSettings& settings) {
  validate(settings);
  if (layers.size != settings.size || layers.offsets.size() != std::size_t(layers.size) * layers.size + 1)
    throw std::invalid_argument("make_stack: the layers do not match the settings' map size");
  Stack stack;
  stack.name = std::move(name);
  stack.settings = settings;
  const int size = settings.size, n = settings.grid, taps = settings.filter_taps, radius = taps / 2;
  const double steps = double(n - 1);
  const auto to_grid = [&](double depth) { return std::int32_t(std::lround(std::clamp(depth, 0.0, 1.0) * steps)); };

  // The shadow map: the first surface of each texel on the grid, the far plane where none.
  std::vector<std::int32_t> first(std::size_t(size) * size, n - 1);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const auto hits = layers.texel(x, y);
      if (!hits.empty()) first[std::size_t(y) * size + x] = to_grid(hits[0].depth);
    }

  const std::vector<double> weights = kernel_weights(taps, settings.filter_sigma);
  stack.kernel_offsets.reserve(first.size() + 1);
  stack.kernel_offsets.push_back(0);
  std::map<std::int32_t, double> merged;
  StackStats& stats = stack.stats;
  stats.texels = std::int64_t(first.size());
  stats.truncated_texels = std::int64_t(layers.truncated_texels);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const auto hits = layers.texel(x, y);
      const std::int32_t texel = y * size + x;
      if (!hits.empty()) {
        // Z: the kernel's first surfaces, one atom per grid index (ascending), in a fixed order of
        // summation so that every build gives the same bits.
        merged.clear();
        for (int j = 0; j < taps; ++j)
          for (int k = 0; k < taps; ++k) {
            const int sx = std::clamp(x + k - radius, 0, size - 1), sy = std::clamp(y + j - radius, 0, size - 1);
            merged[first[std::size_t(sy) * size + sx]] += weights[std::size_t(j) * taps + k];
          }
        for (const auto& [index, weight] : merged) stack.atoms.push_back({index, weight});
        ++stats.covered_texels;
        stats.max_layers = std::max<std::int64_t>(stats.max_layers, std::int64_t(hits.size()));
      }
      stack.kernel_offsets.push_back(std::uint32_t(stack.atoms.size()));
      const auto kernel = stack.kernel(texel);
      for (std::size_t layer = 0; layer < hits.size(); ++layer) {
        const reference::LayerHit& hit = hits[layer];
        Fragment f;
        f.texel = texel;
        f.layer = std::int32_t(layer);
        double bias = radius * (std::fabs(hit.depth_gradient.x) + std::fabs(hit.depth_gradient.y)) + 2.0 / steps;
        if (bias > settings.max_bias) {
          bias = settings.max_bias;
          ++stats.bias_capped;
        }
        f.receiver = hit.depth - bias;
        // Grid points i with i / (n - 1) < zf.
        f.cutoff = std::int32_t(std::clamp(std::ceil(f.receiver * steps), 0.0, steps + 1.0));
        for (const GridAtom& a : kernel)
          if (a.index < f.cutoff) f.pcf += a.weight;
        f.pcf = std::min(f.pcf, 1.0);
        f.counted = hit.faces_light;
        stack.fragments.push_back(f);
        ++stats.fragments;
        if (f.counted) {
          ++stats.counted;
          if (f.pcf == 0.0) ++stats.lit;
        }
      }
    }
  return stack;
}

Stack build_stack(std::string name, const scene::Scene& scene, const StackSettings& settings) {
  validate(settings);
  reference::LayerSettings layer_settings;
  layer_settings.size = settings.size;
  layer_settings.max_layers = settings.max_layers;
  layer_settings.threads = settings.threads;
  return make_stack(std::move(name), reference::trace_layers(scene, layer_settings), settings);
}

// ---- Serialization (for the broadcast to MPI ranks and the checkpoint's fingerprint) -----------

namespace {

struct Writer {
  std::vector<char> bytes;
  template <typename T>
  void put(const T& value) {
    const char* p = reinterpret_cast<const char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  template <typename T>
  void put_vector(const std::vector<T>& values) {
    put(std::uint64_t(values.size()));
    const char* p = reinterpret_cast<const char*>(values.data());
    bytes.insert(bytes.end(), p, p + values.size() * sizeof(T));
  }
};

struct Reader {
  std::span<const char> bytes;
  std::size_t at = 0;
  void need(std::size_t count) const {
    if (count > bytes.size() - at) throw std::runtime_error("stack: truncated serialized data");
  }
  template <typename T>
  T get() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return value;
  }
  template <typename T>
  std::vector<T> get_vector() {
    const auto count = get<std::uint64_t>();
    if (count > (bytes.size() - at) / sizeof(T)) throw std::runtime_error("stack: truncated serialized data");
    std::vector<T> values(count);
    std::memcpy(values.data(), bytes.data() + at, count * sizeof(T));
    at += count * sizeof(T);
    return values;
  }
};

constexpr std::uint64_t kMagic = 0x31304b4354534d4dull; // "MMSTCK01"

// Fragments travel as plain fields (the struct has padding whose bytes are unspecified).
struct PackedFragment {
  std::int32_t texel, layer, cutoff, counted;
  double receiver, pcf;
};

} // namespace

std::vector<char> Stack::serialize() const {
  Writer w;
  w.put(kMagic);
  w.put_vector(std::vector<char>(name.begin(), name.end()));
  w.put(settings.size), w.put(settings.grid), w.put(settings.filter_taps), w.put(settings.filter_sigma);
  w.put(settings.max_layers), w.put(settings.max_bias);
  w.put_vector(kernel_offsets);
  std::vector<std::int32_t> indices;
  std::vector<double> weights;
  for (const GridAtom& a : atoms) indices.push_back(a.index), weights.push_back(a.weight);
  w.put_vector(indices);
  w.put_vector(weights);
  std::vector<PackedFragment> packed;
  packed.reserve(fragments.size());
  for (const Fragment& f : fragments)
    packed.push_back({f.texel, f.layer, f.cutoff, f.counted ? 1 : 0, f.receiver, f.pcf});
  w.put_vector(packed);
  w.put(stats);
  return std::move(w.bytes);
}

Stack Stack::deserialize(std::span<const char> bytes) {
  Reader r{bytes};
  if (r.get<std::uint64_t>() != kMagic) throw std::runtime_error("stack: not a serialized stack");
  Stack s;
  const std::vector<char> name = r.get_vector<char>();
  s.name.assign(name.begin(), name.end());
  s.settings.size = r.get<int>();
  s.settings.grid = r.get<int>();
  s.settings.filter_taps = r.get<int>();
  s.settings.filter_sigma = r.get<float>();
  s.settings.max_layers = r.get<int>();
  s.settings.max_bias = r.get<double>();
  s.kernel_offsets = r.get_vector<std::uint32_t>();
  const auto indices = r.get_vector<std::int32_t>();
  const auto weights = r.get_vector<double>();
  if (indices.size() != weights.size()) throw std::runtime_error("stack: malformed atoms");
  for (std::size_t i = 0; i < indices.size(); ++i) s.atoms.push_back({indices[i], weights[i]});
  for (const PackedFragment& p : r.get_vector<PackedFragment>())
    s.fragments.push_back({p.texel, p.layer, p.cutoff, p.receiver, p.pcf, p.counted != 0});
  s.stats = r.get<StackStats>();
  const std::size_t texels = std::size_t(s.settings.size) * std::size_t(s.settings.size);
  if (s.kernel_offsets.size() != texels + 1 || s.kernel_offsets.back() != s.atoms.size())
    throw std::runtime_error("stack: malformed kernel offsets");
  for (const Fragment& f : s.fragments)
    if (f.texel < 0 || std::size_t(f.texel) >= texels) throw std::runtime_error("stack: malformed fragment");
  return s;
}

std::uint64_t Stack::fingerprint() const {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (char c : serialize()) hash = (hash ^ std::uint8_t(c)) * 0x100000001b3ull;
  return hash;
}

} // namespace msm::evaluate
