// msm_web_kernels OUT.json OUT.bin: the inputs of the browser test of the shared math
// (test/math.test.mjs) and the C++ library's results on them, computed by the same dispatcher
// (kernels.h) that the WebGL 2 fragment shader runs. For each function id: 'count' inputs that are
// meaningful for it (biased moments of random depth distributions in every storage path the
// package uses, receivers on, just in front of and behind a surface, storage words, rounding
// ties). OUT.bin holds, per function in the order of OUT.json, the inputs then the results, each a
// KernelIO as 12 little-endian uint32 words (a and b as float bits, then u).
#include "kernels.h"
#include "test_distributions.h"

#include "msm/techniques.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace msm;

constexpr int kInputs = 4096; // per function

const char* const kNames[] = {"fma",
                              "moments4",
                              "theta4_star",
                              "theta4_star_inverse",
                              "pack_unorm16x4",
                              "unpack_unorm16x4",
                              "apply_bias",
                              "hamburger4_bounds",
                              "nl_from_moments",
                              "nl_moments_from",
                              "nl_psi4",
                              "nl_psi4_inverse",
                              "nl_pack64",
                              "nl_unpack64",
                              "nl_pack32",
                              "nl_unpack32",
                              "nl_shadow",
                              "three_generate",
                              "three_shadow",
                              "three_store",
                              "three_sat_texel",
                              "three_depth_per_texel",
                              "soft_blocker4",
                              "soft_shadow4",
                              "three_soft_shadow",
                              "overdarken",
                              "three_nl64_bilinear"};
static_assert(sizeof(kNames) / sizeof(kNames[0]) == MSM_WK_COUNT);

class Inputs {
 public:
  explicit Inputs(uint64_t seed) : rng_(seed) {}
  float uni(float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng_); }
  float log_uniform(float lo, float hi) { return std::exp(uni(std::log(lo), std::log(hi))); }
  bool chance(double p) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < p; }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  uint32_t word() { return uint32_t(rng_()); }

  // A random depth distribution on [-1,1] (flat receivers, i.e. single depths, in a quarter).
  test::Distribution distribution() {
    if (chance(0.25)) return test::Distribution{{double(uni(-1.0f, 1.0f))}, {1.0}};
    return test::random_distribution(rng_, -1.0, 1.0);
  }
  // A receiver near one of d's depths: on it, just in front or behind, or anywhere.
  float receiver(const test::Distribution& d) {
    float surface = float(d.z[size_t(integer(0, int(d.z.size()) - 1))]);
    int k = integer(0, 3);
    if (k == 0) return surface;
    if (k == 3) return uni(-1.0f, 1.0f);
    return surface + (k == 1 ? -1.0f : 1.0f) * log_uniform(1e-5f, 0.1f);
  }
  // What the package's 64-bit MSM reads: Θ4*, 16-bit storage, inverse, bias; or float moments
  // with the float bias.
  vec4 stored_moments(const test::Distribution& d) {
    vec4 b = test::moments4f(d);
    if (chance(0.5)) return msm_apply_bias(b, msm_moment_bias(MSM_REP_SIGNED_FLOAT));
    vec4 q = msm_quantize_unorm16(msm_theta4_star(b));
    return msm_apply_bias(msm_theta4_star_inverse(q), msm_moment_bias(MSM_REP_SIGNED_THETA4));
  }
  NonLinearMoments nonlinear(const test::Distribution& d) {
    NonLinearMoments m = msm_nl_from_filtered(test::moments4f(d));
    int k = integer(0, 2);
    return k == 0 ? m : k == 1 ? msm_nl_quantize64(m) : msm_nl_quantize32(m);
  }
  // A value to be stored in UNORM16: mostly in [0,1], some outside, some on a tie k + 1/2.
  float unorm_value() {
    int k = integer(0, 9);
    if (k == 0) return uni(-0.2f, 1.2f);
    float q = float(integer(0, 65534));
    if (k == 1) return (q + 0.5f) / 65535.0f;
    if (k == 2) return q / 65535.0f;
    return uni(0.0f, 1.0f);
  }

 private:
  std::mt19937_64 rng_;
};

// Two neighbouring 64-bit texels and a receiver between them: texels (i, j) and (i + 1, j) of a
// plane 0.3 to 3 m below a point light of range 20 m (a 128² cube face, the package's 9-tap blur,
// σ = 2.4), the receiver on the plane with the non-linear depth bias. The plane is lit: moments
// about depth 0 lose what these texels hold (ξ4 ~ 1e-7, a second depth of weight ~1e-3) and shadow
// some receivers, which msm_nl_bilinear's moments about the mean keep (same_as_renderer checks it).
void nl64_neighbours(KernelIO& x, Inputs& g) {
  const int n = 128, taps = 9;
  const float below = g.uni(0.3f, 3.0f), range = 20.0f, fx = g.uni(0.0f, 1.0f);
  auto distance = [&](float i, float j) {
    float s = (i + 0.5f) * 2.0f / n - 1.0f, t = (j + 0.5f) * 2.0f / n - 1.0f;
    return below * std::sqrt(1.0f + s * s + t * t);
  };
  auto blurred = [&](int i, int j) {
    vec4 sum(0.0f);
    for (int l = 0; l < taps; ++l)
      for (int k = 0; k < taps; ++k) {
        float depth = msm_local_light_depth(distance(float(i + k - taps / 2), float(j + l - taps / 2)), range);
        sum += msm_gaussian_weight(k, taps, 2.4f) * msm_gaussian_weight(l, taps, 2.4f) *
               msm_moments4(msm_signed_depth(depth));
      }
    return sum;
  };
  int i = g.integer(taps, n - taps - 1), j = g.integer(taps, n - taps - 1);
  x.u =
      uvec4(msm_nl_pack64(msm_nl_from_filtered(blurred(i, j))), msm_nl_pack64(msm_nl_from_filtered(blurred(i + 1, j))));
  x.a =
      vec4(fx, msm_local_light_receiver_depth(distance(float(i) + fx, float(j)), range, MSM_DEPTH_BIAS_NONLINEAR, 2.0f),
           0.0f, 0.0f);
}

KernelIO make_input(int id, Inputs& g) {
  KernelIO x{vec4(0.0f), vec4(0.0f), uvec4(0u)};
  test::Distribution d = g.distribution();
  switch (id) {
  case MSM_WK_FMA: { // the cancelling differences of the Hankel pivots, and random triples
    vec4 b = test::moments4f(d);
    int k = g.integer(0, 2);
    x.a = k == 0   ? vec4(-b[0], b[0], b[1], 0.0f)
          : k == 1 ? vec4(-b[0], b[1], b[2], 0.0f)
                   : vec4(g.uni(-2, 2), g.uni(-2, 2), g.uni(-2, 2), 0.0f);
    break;
  }
  case MSM_WK_MOMENTS4: x.a[0] = g.chance(0.05) ? float(g.integer(0, 4)) * 0.25f : g.uni(0.0f, 1.0f); break;
  case MSM_WK_THETA4_STAR: x.a = test::moments4f(d); break;
  case MSM_WK_THETA4_STAR_INVERSE:
    x.a = g.chance(0.5) ? msm_quantize_unorm16(msm_theta4_star(test::moments4f(d)))
                        : vec4(g.uni(0, 1), g.uni(0, 1), g.uni(0, 1), g.uni(0, 1));
    break;
  case MSM_WK_PACK_UNORM16: x.a = vec4(g.unorm_value(), g.unorm_value(), g.unorm_value(), g.unorm_value()); break;
  case MSM_WK_UNPACK_UNORM16:
  case MSM_WK_NL_UNPACK64:
  case MSM_WK_NL_UNPACK32: x.u = uvec4(g.word(), g.word(), 0u, 0u); break;
  case MSM_WK_APPLY_BIAS:
    x.a = test::moments4f(d);
    x.u[0] = uint32_t(g.chance(0.5) ? MSM_REP_SIGNED_FLOAT : MSM_REP_SIGNED_THETA4);
    break;
  case MSM_WK_HAMBURGER4_BOUNDS:
    x.a = g.stored_moments(d);
    x.b[0] = g.receiver(d);
    break;
  case MSM_WK_NL_FROM_MOMENTS: // Φ's precondition, the float bias, in most; unbiased ones too
    x.a = test::moments4f(d);
    if (g.chance(0.9)) x.a = msm_apply_bias(x.a, msm_moment_bias(MSM_REP_SIGNED_FLOAT));
    break;
  case MSM_WK_NL_MOMENTS_FROM:
  case MSM_WK_NL_PACK64:
  case MSM_WK_NL_PACK32:
  case MSM_WK_NL_SHADOW: {
    NonLinearMoments m = g.nonlinear(d);
    x.a = vec4(m.y1, m.y2, m.v2, m.xi4);
    x.b[0] = g.receiver(d);
    break;
  }
  case MSM_WK_NL_PSI4: x.a[0] = g.chance(0.05) ? 0.0f : g.log_uniform(1e-8f, 0.5f); break;
  case MSM_WK_NL_PSI4_INVERSE:
    x.a[0] = g.chance(0.2) ? msm_nl_psi4_decode6(uint32_t(g.integer(0, 63))) : g.uni(0.0f, 1.0f);
    break;
  case MSM_WK_THREE_GENERATE:
    x.a[0] = g.chance(0.05) ? float(g.integer(0, 4)) * 0.25f : g.uni(0.0f, 1.0f);
    x.u[0] = uint32_t(g.integer(MSM_THREE_HAMBURGER_64, MSM_THREE_NL32));
    break;
  case MSM_WK_THREE_STORE: { // blurred channels in each technique's basis
    int t = g.integer(MSM_THREE_HAMBURGER_64, MSM_THREE_NL64);
    vec4 b = test::moments4f(d);
    x.a = t == MSM_THREE_HAMBURGER_64 ? msm_theta4_star(b) : b;
    x.u[0] = uint32_t(t);
    break;
  }
  case MSM_WK_THREE_SHADOW: { // a texel as the package stores it, a receiver near its depths
    int t = g.integer(MSM_THREE_HAMBURGER_64, MSM_THREE_NL64);
    vec4 b = test::moments4f(d);
    x.a = t == MSM_THREE_HAMBURGER_64 ? msm_quantize_unorm16(msm_theta4_star(b))
          : t == MSM_THREE_NL64       ? msm_three_store(t, b)
                                      : b;
    x.b[0] = msm_unit_depth(g.receiver(d));
    x.u[0] = uint32_t(t);
    break;
  }
  case MSM_WK_THREE_SAT_TEXEL:
    x.a[0] = g.chance(0.05) ? float(g.integer(0, 4)) * 0.25f : g.uni(0.0f, 1.0f);
    x.u[0] = uint32_t(g.chance(0.5) ? MSM_THREE_SOFT_KERNEL : g.integer(2, MSM_SOFT_MAX_KERNEL_WIDTH4));
    break;
  case MSM_WK_THREE_DEPTH_PER_TEXEL: { // a plane's derivatives: dt/dx, dt/dy and g · dt, with noise
    vec2 slope(g.uni(-0.03f, 0.03f), g.uni(-0.03f, 0.03f));
    vec2 tx(g.uni(-2.0f, 2.0f), g.uni(-2.0f, 2.0f)), ty(g.uni(-2.0f, 2.0f), g.uni(-2.0f, 2.0f));
    x.a = vec4(tx, dot(slope, tx) + (g.chance(0.2) ? g.uni(-1e-3f, 1e-3f) : 0.0f), 0.0f);
    x.b = vec4(ty, dot(slope, ty), 0.0f);
    if (g.chance(0.05)) x.b = vec4(tx * 2.0f, x.a[2] * 2.0f, 0.0f); // degenerate
    break;
  }
  case MSM_WK_SOFT_BLOCKER4:
  case MSM_WK_SOFT_SHADOW4: { // a region's average of quantized texels, a receiver near its depths
    uint32_t scale = msm_sat_scale(MSM_THREE_SOFT_KERNEL * MSM_THREE_SOFT_KERNEL);
    vec4 q = msm_theta4_star(test::moments4f(d));
    x.a = msm_sat_dequantize(msm_sat_quantize(q, scale), scale);
    x.b[0] = g.receiver(d);
    x.u[0] = scale;
    break;
  }
  case MSM_WK_OVERDARKEN: { // intensities from lit to full shadow, some exact; the option's factors
    x.a[0] = g.chance(0.1) ? float(g.integer(0, 4)) * 0.25f : g.uni(0.0f, 1.0f);
    x.a[1] = g.chance(0.2) ? (g.chance(0.5) ? 1.0f : MSM_OVERDARKEN_DEFAULT) : g.uni(0.5f, 1.0f);
    break;
  }
  case MSM_WK_THREE_NL64_BILINEAR: nl64_neighbours(x, g); break;
  default: break;
  }
  return x;
}

// The soft lookup's depth map: 64 x 64 texels of a sloped ground, a box of blockers over it, a
// second box at another depth and a few single texels.
constexpr int kTableSize = 64;
std::vector<float> soft_depths() {
  std::vector<float> d(size_t(kTableSize * kTableSize));
  std::mt19937_64 rng(0x5a7);
  for (int y = 0; y < kTableSize; ++y)
    for (int x = 0; x < kTableSize; ++x) {
      float depth = 0.6f + 0.002f * float(x) - 0.001f * float(y);
      if (x >= 20 && x < 36 && y >= 24 && y < 40) depth = 0.3f;
      if (x >= 40 && x < 48 && y >= 10 && y < 30) depth = 0.45f;
      if (rng() % 61 == 0) depth = std::uniform_real_distribution<float>(0.1f, 0.7f)(rng);
      d[size_t(y * kTableSize + x)] = depth;
    }
  return d;
}
// Its summed-area table as sat.h defines it (wrapping uint running sums): what the renderer's
// SatBuilder makes, and what the package's passes (src/soft.js) must make in WebGL.
std::vector<uvec4> soft_table(const std::vector<float>& depths, int kernel_width) {
  std::vector<uvec4> t(size_t(kTableSize * kTableSize));
  for (int y = 0; y < kTableSize; ++y)
    for (int x = 0; x < kTableSize; ++x) {
      uvec4 v = msm_three_sat_texel(depths[size_t(y * kTableSize + x)], kernel_width);
      if (x > 0) v += t[size_t(y * kTableSize + x - 1)];
      t[size_t(y * kTableSize + x)] = v;
    }
  for (int y = 1; y < kTableSize; ++y)
    for (int x = 0; x < kTableSize; ++x) t[size_t(y * kTableSize + x)] += t[size_t((y - 1) * kTableSize + x)];
  return t;
}

KernelIO soft_input(Inputs& g) {
  KernelIO x{vec4(0.0f), vec4(0.0f), uvec4(uint32_t(MSM_THREE_SOFT_KERNEL), kTableSize, kTableSize, 0u)};
  vec2 t(g.uni(-0.05f, 1.05f), g.uni(-0.05f, 1.05f));
  vec2 texel = t * float(kTableSize);
  float ground = 0.6f + 0.002f * (texel.x - 0.5f) - 0.001f * (texel.y - 0.5f);
  float depth = g.chance(0.8) ? ground : g.uni(0.2f, 0.8f);
  x.a = vec4(t, depth, g.log_uniform(0.002f, 0.05f));
  x.b =
      vec4(5.0f, 0.02f, g.chance(0.5) ? 0.002f : g.uni(-0.02f, 0.02f), g.chance(0.5) ? -0.001f : g.uni(-0.02f, 0.02f));
  return x;
}

// The renderer's technique (techniques.h) that each of the package's techniques is.
int renderer_technique(uint32_t t) {
  if (t == uint32_t(MSM_THREE_HAMBURGER_64)) return MSM_TECH_HAMBURGER_64;
  if (t == uint32_t(MSM_THREE_NL32)) return MSM_TECH_NL32;
  return t == uint32_t(MSM_THREE_NL64) ? MSM_TECH_NL64 : MSM_TECH_HAMBURGER_128;
}

// The package's per-texel steps (msm_three.h) are the renderer's: identical results in C++, so
// that the browser's comparison with msm_web_kernel is one with the renderer's technique too.
bool same_as_renderer(int id, const KernelIO& x, const KernelIO& r) {
  int t = renderer_technique(x.u[0]);
  if (id == MSM_WK_THREE_GENERATE) {
    vec4 want = msm_technique_generate(t, x.a[0], msm_technique_default_params(t)).a;
    // The 32-bit map's RGBA8 texel holds the renderer's word (THREE_STORE has no 32-bit inputs: its
    // bytes differ by whole steps where Ψ4 rounds differently on WebGL, which nl_pack32 bounds).
    if (t == MSM_TECH_NL32 && msm_three_word_from_rgba8(msm_three_store(MSM_THREE_NL32, r.a)) != msm_nl32_encode(r.a))
      return false;
    vec4 stored = msm_three_store(int(x.u[0]), r.a);
    // The renderer's 64-bit map rounds to UNORM16 on the write; msm_three_store does that in the shader.
    return r.a == want && (t != MSM_TECH_HAMBURGER_64 || stored == msm_quantize_unorm16(want));
  }
  if (id == MSM_WK_THREE_STORE) {
    vec4 want = t == MSM_TECH_HAMBURGER_64 ? msm_quantize_unorm16(x.a)
                : t == MSM_TECH_NL64       ? msm_nl64_encode(x.a)
                                           : x.a;
    return r.a == want;
  }
  // The 64-bit non-linear shading of one texel (decode, Algorithm 3) has no twin in techniques.h
  // (the renderer's shading_nonlinear.glsl calls nonlinear.h's functions): compared with the C++
  // build alone.
  if (id == MSM_WK_THREE_NL64_BILINEAR) return r.a[0] <= 1e-3f; // the lit plane's receivers
  if (id == MSM_WK_THREE_SAT_TEXEL) { // the renderer's mssm4 texel, quantized as its tables (sat_common.glsl)
    int w = int(x.u[0]);
    vec4 moments = msm_technique_generate(MSM_TECH_MSSM4, x.a[0], msm_technique_default_params(MSM_TECH_MSSM4)).a;
    return r.u == msm_sat_quantize(moments, msm_sat_scale(w * w));
  }
  if (id == MSM_WK_THREE_SHADOW && t != MSM_TECH_NL64) {
    float want = msm_technique_shadow(t, MsmTexel(x.a, vec4(0.0f)), x.b[0], msm_technique_default_params(t));
    return std::bit_cast<uint32_t>(r.a[0]) == std::bit_cast<uint32_t>(want);
  }
  return true;
}

void put(std::vector<uint32_t>& words, const KernelIO& x) {
  for (int i = 0; i < 4; ++i) words.push_back(std::bit_cast<uint32_t>(x.a[i]));
  for (int i = 0; i < 4; ++i) words.push_back(std::bit_cast<uint32_t>(x.b[i]));
  for (int i = 0; i < 4; ++i) words.push_back(x.u[i]);
}

} // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: msm_web_kernels OUT.json OUT.bin\n");
    return 2;
  }
  // The lookup's settings are the renderer's mssm4 defaults.
  if (msm_three_soft_params() != msm_technique_default_params(MSM_TECH_MSSM4)) {
    std::fprintf(stderr, "msm_web_kernels: the package's mssm4 parameters are not the renderer's\n");
    return 1;
  }
  const std::vector<float> depths = soft_depths();
  const std::vector<uvec4> table = soft_table(depths, MSM_THREE_SOFT_KERNEL);
  auto fetch = [&](int x, int y, int) {
    return x < 0 || y < 0 ? uvec4(0u)
                          : table[size_t(std::min(y, kTableSize - 1) * kTableSize + std::min(x, kTableSize - 1))];
  };
  std::vector<uint32_t> words;
  std::string json = "{\"words_per_io\": 12, \"functions\": [";
  for (int id = 0; id < MSM_WK_COUNT; ++id) {
    Inputs g(0x5eed0000u + uint64_t(id));
    std::vector<KernelIO> in;
    for (int n = 0; n < kInputs; ++n) in.push_back(id == MSM_WK_THREE_SOFT_SHADOW ? soft_input(g) : make_input(id, g));
    for (const KernelIO& x : in) put(words, x);
    for (const KernelIO& x : in) {
      KernelIO r = id == MSM_WK_THREE_SOFT_SHADOW ? msm_web_soft_kernel(fetch, x) : msm_web_kernel(id, x);
      if (id == MSM_WK_THREE_NL64_BILINEAR && !same_as_renderer(id, x, r)) {
        std::fprintf(stderr,
                     "msm_web_kernels: %s shadows the lit plane's receiver by %.9g at a = (%.9g, %.9g), texels "
                     "0x%08x 0x%08x and 0x%08x 0x%08x\n",
                     kNames[id], r.a[0], x.a[0], x.a[1], x.u[0], x.u[1], x.u[2], x.u[3]);
        return 1;
      }
      if (!same_as_renderer(id, x, r)) {
        std::fprintf(stderr,
                     "msm_web_kernels: %s differs from the renderer's technique at a = (%.9g, %.9g, %.9g, %.9g), "
                     "b.x = %.9g, technique %u\n",
                     kNames[id], x.a[0], x.a[1], x.a[2], x.a[3], x.b[0], x.u[0]);
        return 1;
      }
      put(words, r);
    }
    json += std::string(id ? ", " : "") + "{\"id\": " + std::to_string(id) + ", \"name\": \"" + kNames[id] +
            "\", \"count\": " + std::to_string(kInputs) + "}";
  }
  // The table after the functions' words, then its depth map (float bits).
  json += "], \"table\": {\"width\": " + std::to_string(kTableSize) + ", \"height\": " + std::to_string(kTableSize) +
          ", \"offset\": " + std::to_string(words.size()) +
          ", \"depths\": " + std::to_string(words.size() + 4 * table.size()) + "}}\n";
  for (const uvec4& v : table)
    for (int i = 0; i < 4; ++i) words.push_back(v[i]);
  for (float d : depths) words.push_back(std::bit_cast<uint32_t>(d));
  std::FILE* j = std::fopen(argv[1], "wb");
  std::FILE* b = std::fopen(argv[2], "wb");
  bool ok = j && b && std::fwrite(json.data(), 1, json.size(), j) == json.size() &&
            std::fwrite(words.data(), sizeof(uint32_t), words.size(), b) == words.size();
  ok = (j && std::fclose(j) == 0) && ok;
  ok = (b && std::fclose(b) == 0) && ok;
  if (!ok) {
    std::fprintf(stderr, "msm_web_kernels: cannot write %s and %s\n", argv[1], argv[2]);
    return 1;
  }
  return 0;
}
