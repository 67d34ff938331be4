// Cost of each per-texel reconstruction on the CPU, per call, over a ring of 4096 precomputed
// inputs (biased moments of random two-surface kernels and fragment depths), so the compiler
// cannot fold anything and the branches see realistic variety.
#include "msm/msm.h"

#include <benchmark/benchmark.h>

#include <random>
#include <vector>

namespace {

using namespace msm;

struct Input {
  vec4 b;      // biased moments for [-1,1] depth
  vec4 b_unit; // biased moments for [0,1] depth
  vec4 q16;    // Θ4*-transformed 16-bit storage value
  NonLinearMoments nl;
  Moments6 b6;     // biased six moments for [-1,1] depth
  vec4 trig;       // biased trigonometric moments, [0,1] depth
  vec4 csm0, csm1; // four Fourier terms of a convolution shadow map, [0,1] depth
  float zf;        // fragment depth in [-1,1]
};

const std::vector<Input>& inputs() {
  static const std::vector<Input> data = [] {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<Input> v(4096);
    for (Input& in : v) {
      float z1 = 2.0f * u(rng) - 1.0f, z2 = 2.0f * u(rng) - 1.0f, w = u(rng);
      vec4 m = mix(msm_moments4(z1), msm_moments4(z2), w);
      vec4 mu = mix(msm_moments4(msm_unit_depth(z1)), msm_moments4(msm_unit_depth(z2)), w);
      in.b = msm_apply_bias(m, msm_moment_bias(MSM_REP_SIGNED_FLOAT));
      in.b_unit = msm_apply_bias(mu, msm_moment_bias(MSM_REP_UNIT_FLOAT));
      in.q16 = msm_quantize_unorm16(msm_theta4_star(m));
      in.nl = msm_nl_quantize64(msm_nl_from_filtered(m));
      Moments6 m6 = msm_moments6_mix(msm_moments6(z1), msm_moments6(z2), w);
      in.b6 = msm_apply_bias6(m6, msm_moment_bias6(MSM_REP6_FLOAT));
      float u1 = msm_unit_depth(z1), u2 = msm_unit_depth(z2);
      in.trig = msm_trig_bias(mix(msm_trig_moments(u1), msm_trig_moments(u2), w));
      in.csm0 = mix(msm_csm_basis_texel(u1, 0), msm_csm_basis_texel(u2, 0), w);
      in.csm1 = mix(msm_csm_basis_texel(u1, 1), msm_csm_basis_texel(u2, 1), w);
      in.zf = 2.0f * u(rng) - 1.0f;
    }
    return v;
  }();
  return data;
}

template <class F>
void run(benchmark::State& state, F f) {
  const std::vector<Input>& in = inputs();
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f(in[i]));
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}

void Hamburger4Lower(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_hamburger4_lower(x.b, x.zf); });
}
void Hamburger4Bounds(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_hamburger4_bounds(x.b, x.zf); });
}
void Hamburger4From16Bit(benchmark::State& s) {
  run(s, [](const Input& x) {
    vec4 b = msm_apply_bias(msm_theta4_star_inverse(x.q16), msm_moment_bias(MSM_REP_SIGNED_THETA4));
    return msm_hamburger4_lower(b, x.zf);
  });
}
void Hausdorff4Lower(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_hausdorff4_lower(x.b_unit, msm_unit_depth(x.zf), 0.0f, 1.0f); });
}
void Canonical4(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_hamburger4_canonical(x.b, x.zf); });
}
void NonLinearShadow(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_nl_shadow(x.nl, x.zf); });
}
void NonLinearEncode64(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_nl_pack64(msm_nl_from_moments(x.b)); });
}
void NonLinearEncode32(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_nl_pack32(msm_nl_from_moments(x.b)); });
}
void Vsm(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_vsm_shadow(vec2(x.b[0], x.b[1]), x.zf); });
}
void Evsm4(benchmark::State& s) {
  run(s, [](const Input& x) {
    return msm_evsm4_shadow(x.b, x.zf, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT, MSM_EVSM_MIN_VARIANCE_FLOAT);
  });
}
void Esm(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_esm_shadow(x.b_unit[0] + 1.0f, msm_unit_depth(x.zf)); });
}
void Evsm2(benchmark::State& s) {
  run(s, [](const Input& x) {
    return msm_evsm2_shadow(vec2(x.b[0], x.b[1]), x.zf, MSM_EVSM_C_64BIT, MSM_EVSM_MIN_VARIANCE_HALF);
  });
}
void Csm4Terms(benchmark::State& s) {
  run(s, [](const Input& x) {
    CsmParams p = msm_csm_default_params();
    p.terms = 4;
    float xf = msm_csm_receiver(msm_unit_depth(x.zf), p);
    return msm_csm_resolve(msm_csm_texel_terms(x.csm0, xf, 0, p) + msm_csm_texel_terms(x.csm1, xf, 1, p), p);
  });
}
void Hamburger6Lower(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_hamburger6_lower(x.b6, x.zf); });
}
void Hamburger6Blend(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_hamburger6_blend(x.b6, x.zf, 0.5f); });
}
void Blocker4(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_blocker4(x.b, x.zf).depth; });
}
void Blocker6(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_blocker6(x.b6, x.zf).depth; });
}
void Trigonometric(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_trig_lower(x.trig, msm_unit_depth(x.zf)); });
}
void Theta4StarInverse(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_theta4_star_inverse(x.q16); });
}
void Theta4Inverse(benchmark::State& s) {
  run(s, [](const Input& x) { return msm_theta4_inverse(x.q16); });
}

BENCHMARK(Vsm);
BENCHMARK(Esm);
BENCHMARK(Evsm2);
BENCHMARK(Evsm4);
BENCHMARK(Csm4Terms);
BENCHMARK(Hamburger4Lower);
BENCHMARK(Hamburger4Bounds);
BENCHMARK(Hamburger4From16Bit);
BENCHMARK(Hausdorff4Lower);
BENCHMARK(Canonical4);
BENCHMARK(Trigonometric);
BENCHMARK(Hamburger6Lower);
BENCHMARK(Hamburger6Blend);
BENCHMARK(Blocker4);
BENCHMARK(Blocker6);
BENCHMARK(NonLinearShadow);
BENCHMARK(NonLinearEncode64);
BENCHMARK(NonLinearEncode32);
BENCHMARK(Theta4Inverse);
BENCHMARK(Theta4StarInverse);

} // namespace
