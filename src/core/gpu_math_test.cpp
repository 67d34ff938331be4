// The shared math of include/msm/ run in a compute shader on the Vulkan device (MSM_DEVICE;
// lavapipe here) agrees with its C++ build. gpu/kernels.h is the one dispatcher that both compile:
// gpu/kernels.comp runs msm_test_kernel() over a storage buffer, this test runs it on the CPU over
// the same inputs and compares, per function id, on 1e5 random inputs that are meaningful for the
// function: biased moments of random depth distributions (test_distributions.h; single depths,
// i.e. flat receivers, two depths, Diracs, continuous) in every storage representation, receivers
// on, just in front of and behind the surface, storage words, rounding ties, degenerate roots
// (fixed seeds; MSM_GPU_MATH_SEED=n draws others). Validation is on (VulkanTest): any validation
// message fails the test.
//
// Why the two builds differ at all, and what the tolerances allow for:
//  - transcendentals (sin, cos, atan, exp, log) are correctly rounded on neither side; Vulkan
//    bounds the device's (exp: 3 + 2|x| ulp; sin/cos: 2^-11 absolute on [-π, π]);
//  - without `precise` the device compiler may contract a * b + c into fma and reassociate, and
//    divides as x · (1/y) (Vulkan: 2.5 ulp); GLM sums mat * vec pairwise; the CPU build has
//    -ffp-contract=off;
//  - GLSL's fma() need not be fused, and lavapipe's is not: shared.h's msm_fma is then the exact
//    emulation (msm::vk's probe decides; see GpuMath), which makes fma exact on every device;
//  - the device may flush subnormals to zero (compared as zero here);
//  - UNORM rounding of exact ties k + 1/2 goes either way (GLSL round(), Vulkan's conversion);
//  - reconstructions from nearly singular Hankel/Toeplitz matrices (the bias leaves a smallest
//    eigenvalue ~1e-7) amplify last-bit differences, most of all for flat receivers just behind
//    the surface, and a one-ulp difference can take the other side of a branch.
// Metrics (per input: the largest error over the compared outputs): FIELDS, |difference| of packed
// integer fields in units of their last bit; ULP, distance in units in the last place; ABS,
// |device - cpu| / max(1, |cpu|): absolute for values in [-1,1] (shadow intensities, weights,
// depths), relative for large ones (roots, exponential warps). Each function bounds the max and
// the 99.9th percentile (some also the fraction of inputs that differ at all). The measured values
// are printed as "[gpu-math]" lines; "measured" below is lavapipe
// (Mesa 22.3.6, LLVM 15), where msm_fma is the emulation (see GpuMath).
#include "gpu/kernels.h"
#include "test_distributions.h"

#include "msm/test/vulkan_test.h"
#include "msm/vk/vk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace {

using namespace msm;
static_assert(sizeof(KernelIO) == 48, "KernelIO must match its std430 layout (stride 48)");

constexpr int kInputs = 100000; // random inputs per function
constexpr double kInf = std::numeric_limits<double>::infinity();

// ================================ What is compared, and how closely ================================

enum class Metric { fields, ulp, abs };
// Packed words as bit fields, for Metric::Fields.
enum class Layout { none, unorm16x4, unorm10x3, nl32 };
// How float outputs are read: as they are; or a[0..nodes) as a set of roots (sorted), with weights
// b[0..nodes) if compared (sorted pairs). Nodes beyond ±kFar are one point at infinity: a root
// that escapes to infinity (c2 -> 0 for a single depth; q[3] = 0) comes back as ±1e8 or as
// 1/rounding noise, with either sign, and weight ~0.
enum class Shape { values, nodes };
constexpr float kFar = 1.0e3f;

struct Spec {
  int id;
  const char* name;
  Metric metric;
  int floats;              // compared float outputs: bit i = a[i], bit 4 + i = b[i] (Ulp, Abs)
  Layout layout;           // compared integer fields (Fields)
  double max_tol;          // bound of the largest per-input error
  double p999_tol;         // bound of its 99.9th percentile
  double differ_tol = 1.0; // bound of the fraction of inputs with any difference
  Shape shape = Shape::values;
  int nodes = 0;
  // > 0: output i stores input channel i in UNORM with this many steps (2^n - 1); at an exact
  // tie k + 1/2 either neighbor is accepted (GLM rounds away from zero, lavapipe to even).
  float tie_steps = 0.0f;
  int inputs = kInputs; // random inputs (fewer for the functions with loops: the suite's time)
};

constexpr int A1 = 0x01, A2 = 0x03, A3 = 0x07, A4 = 0x0F, AB3 = 0x77, AB4 = 0xFF;
constexpr Shape Nodes = Shape::nodes, Values = Shape::values;

// Names for the output; tolerances with the measured max / p99.9 and the reason.
const Spec kSpecs[] = {
    // shared.h. fma: one rounding on both sides, exactly: the native fma() where it is fused, else
    // msm_fma_emulated, correctly rounded (lavapipe's native fma() rounds twice: measured up to
    // 100% relative, the exact residual against 0; printed as 'native fma').
    {MSM_K_FMA, "fma", Metric::ulp, A1, Layout::none, 0, 0},
    {MSM_K_SATURATE, "saturate", Metric::ulp, A1, Layout::none, 0, 0}, // measured 0
    // moments.h. Products of z: the same IEEE multiplications (measured 0).
    {MSM_K_MOMENTS4, "moments4", Metric::ulp, A4, Layout::none, 0, 0},
    {MSM_K_MOMENTS6, "moments6", Metric::ulp, AB3, Layout::none, 0, 0},
    // sin/cos of 2πz; lavapipe is within ~1 ulp of libm (measured 2.1e-7 / 2.1e-7), GPUs' sin/cos
    // are typically ~1e-6 absolute.
    {MSM_K_TRIG_MOMENTS, "trig_moments", Metric::abs, A4, Layout::none, 2e-6, 1e-6},
    // Sums of terms up to 32 in another order: a few roundings of partial sums <= 64
    // (measured 2.4e-7 / 2.4e-7).
    {MSM_K_UNIT_TO_SIGNED, "unit_to_signed", Metric::abs, A4, Layout::none, 4e-6, 1e-6},
    // quantize.h. Linear maps; mat * vec in another order (pairwise in GLM) and with other
    // contractions: ~3 roundings of partial sums <= 2^7 for θ4 (bound 2.3e-5; measured 1.9e-6 /
    // 1.9e-6), <= 2^5 for Θ6* (7.2e-7 / 4.8e-7), <= 2 for the rest (<= 1.2e-7 / 1.2e-7).
    {MSM_K_THETA4, "theta4", Metric::abs, A4, Layout::none, 4e-5, 1e-5},
    {MSM_K_THETA4_INVERSE, "theta4_inverse", Metric::abs, A4, Layout::none, 1e-6, 5e-7},
    {MSM_K_THETA4_STAR, "theta4_star", Metric::abs, A4, Layout::none, 1e-6, 5e-7},
    {MSM_K_THETA4_STAR_INVERSE, "theta4_star_inverse", Metric::abs, A4, Layout::none, 1e-6, 5e-7},
    {MSM_K_THETA6_STAR, "theta6_star", Metric::abs, AB3, Layout::none, 4e-6, 2e-6},
    {MSM_K_THETA6_STAR_INVERSE, "theta6_star_inverse", Metric::abs, AB3, Layout::none, 1e-6, 5e-7},
    {MSM_K_THETA2, "theta2", Metric::abs, A2, Layout::none, 1e-6, 5e-7},
    {MSM_K_THETA2_INVERSE, "theta2_inverse", Metric::abs, A2, Layout::none, 1e-6, 5e-7},
    // Packing: exact apart from ties (measured 0; ties rounded the other way: see "ties").
    // Unpacking k / (2^n - 1): GLM multiplies by the rounded reciprocal, the device divides
    // (Vulkan: 2.5 ulp) or does the same (measured 1 / 1).
    {MSM_K_PACK_UNORM16, "pack_unorm16x4", Metric::fields, 0, Layout::unorm16x4, 0, 0, 1.0, Values, 0, 65535.0f},
    {MSM_K_UNPACK_UNORM16, "unpack_unorm16x4", Metric::ulp, A4, Layout::none, 2, 2},
    {MSM_K_PACK_UNORM10, "pack_unorm10x3", Metric::fields, 0, Layout::unorm10x3, 0, 0, 1.0, Values, 0, 1023.0f},
    {MSM_K_UNPACK_UNORM10, "unpack_unorm10x3", Metric::ulp, A3, Layout::none, 2, 2},
    {MSM_K_QUANTIZE6_UNORM16, "quantize6_unorm16", Metric::ulp, AB3, Layout::none, 2, 2, 1.0, Values, 0, 65535.0f},
    {MSM_K_QUANTIZE6_UNORM10, "quantize6_unorm10", Metric::ulp, AB3, Layout::none, 2, 2, 1.0, Values, 0, 1023.0f},
    // bias.h. mix(b, b*, α) as x (1 - a) + y a or x + a (y - x): 2 roundings (measured 0).
    {MSM_K_APPLY_BIAS, "apply_bias", Metric::abs, A4, Layout::none, 5e-7, 2.5e-7},
    {MSM_K_APPLY_BIAS6, "apply_bias6", Metric::abs, AB3, Layout::none, 5e-7, 2.5e-7},
    // roots.h: sqrt and divisions, amplified by close roots (measured 0 / 0). hamburger6.h's cubic
    // (Blinn: atan, cos, sin): a cluster of three roots moves by ~eps^(1/3) (measured 0.011 /
    // 2.6e-3).
    {MSM_K_SOLVE_QUADRATIC, "solve_quadratic", Metric::abs, A2, Layout::none, 1e-3, 1e-5},
    {MSM_K_CUBIC_ROOTS, "cubic_roots", Metric::abs, A3, Layout::none, 0.05, 5e-3},
    // Reconstructions from biased moments; most differences come from flat receivers just behind
    // the surface, where the bound is steep in every intermediate. Measured maxima and p99.9 are
    // the largest over 6 seeds. Four moments: the bounds' divisions and sums (0.024 / 6.2e-5);
    // canonical, two depths, blocker and Φ run the same IEEE operations once fma is exact
    // (0 / 0), but their node of weight ~α is ill-conditioned and may move on other devices.
    // Bounds: measured 1.2e-3 / 4.4e-5 with the edge classes (6 seeds).
    {MSM_K_HAMBURGER4_BOUNDS, "hamburger4_bounds", Metric::abs, A2, Layout::none, 0.01, 2e-4},
    {MSM_K_HAMBURGER4_CANONICAL, "hamburger4_canonical", Metric::abs, AB3, Layout::none, 0.5, 1e-3, 1.0, Nodes, 3},
    // Hausdorff: its four-atom case once divided rounding noise by rounding noise for
    // receivers ~1e-4 behind a surface and differed by up to 1 (p99.9 6.4e-4); from the moments of
    // (z - lo)(hi - z) dZ, with the noise resolved to one side, it differs by 1.5e-3 / 4.0e-5
    // (6 seeds, a third of the inputs from the edge classes, see edge_pool).
    {MSM_K_HAUSDORFF4, "hausdorff4_lower", Metric::abs, A1, Layout::none, 0.01, 2e-4},
    {MSM_K_TWO_DEPTHS, "two_depths_from_three_moments", Metric::abs, A4, Layout::none, 0.1, 2e-4},
    // Six moments: the Hankel solve plus Blinn's cubic (atan, cos, sin). Bounds and blend 6.1e-4
    // / 2.6e-4, canonical 2.3e-3 / 2.9e-4 (nodes of weight ~α), blocker6 7.3e-4 / 2.8e-4, its upper
    // variant 3.4e-3 / 7.3e-4; all without the fixed case in make_inputs, which fails (CPU).
    {MSM_K_HAMBURGER6_BOUNDS, "hamburger6_bounds", Metric::abs, A2, Layout::none, 5e-3, 1e-3},
    {MSM_K_HAMBURGER6_BLEND, "hamburger6_blend", Metric::abs, A1, Layout::none, 5e-3, 1e-3},
    {MSM_K_HAMBURGER6_CANONICAL, "hamburger6_canonical", Metric::abs, AB4, Layout::none, 0.5, 1e-3, 1.0, Nodes, 4},
    {MSM_K_BLOCKER4, "blocker4", Metric::abs, A2, Layout::none, 0.1, 2e-4},
    {MSM_K_BLOCKER4_UPPER, "blocker4_upper", Metric::abs, A2, Layout::none, 0.1, 2e-4},
    {MSM_K_BLOCKER6, "blocker6", Metric::abs, A2, Layout::none, 5e-3, 1e-3},
    {MSM_K_BLOCKER6_UPPER, "blocker6_upper", Metric::abs, A2, Layout::none, 2e-2, 2e-3},
    // Toeplitz LDLᴴ, atan2, a scan for a sign change and Newton steps. When the scan misses the
    // sign change on one side only, that side falls back to the end points (0.24 / 2.9e-4; in the
    // 0.24 case the CPU matches the LP oracle and the device does not): no max bound.
    {MSM_K_TRIG_BOUNDS, "trig_bounds", Metric::abs, A2, Layout::none, 1.0, 1e-3},
    // nonlinear.h. Φ as the two depths above. Ψ4 = log log: measured 2.4e-7 / 1.8e-7. Its
    // inverse exp(exp(l)) / 1e7 with exp(l) <= 14.7: Vulkan's exp bounds give 8.4 ulp · 14.7 +
    // 32 ulp ≈ 160 ulp (measured 109 / 84); unpacked ξ4 <= 0.25 carries that (measured 1.5e-6 /
    // 1.0e-6). Packing: 1 LSB where a value lies on a rounding boundary up to those ulps; inputs
    // decoded from 32 bits lie exactly on Ψ4's 6-bit boundaries (measured 1 / 1, differing 0.49%
    // at 64 bits and 1.6% at 32 bits). Algorithm 3 has no fma and no transcendental: 0 / 0.
    {MSM_K_NL_FROM_MOMENTS, "nl_from_moments", Metric::abs, A4, Layout::none, 0.1, 2e-4},
    {MSM_K_NL_MOMENTS_FROM, "nl_moments_from", Metric::abs, A4, Layout::none, 1e-6, 5e-7},
    {MSM_K_NL_PSI4, "nl_psi4", Metric::abs, A1, Layout::none, 1e-6, 5e-7},
    {MSM_K_NL_PSI4_INVERSE, "nl_psi4_inverse", Metric::ulp, A1, Layout::none, 192, 128},
    {MSM_K_NL_PACK64, "nl_pack64", Metric::fields, 0, Layout::unorm16x4, 1, 1, 0.01},
    {MSM_K_NL_UNPACK64, "nl_unpack64", Metric::abs, A4, Layout::none, 4e-6, 2e-6},
    {MSM_K_NL_PACK32, "nl_pack32", Metric::fields, 0, Layout::nl32, 1, 1, 0.03},
    {MSM_K_NL_UNPACK32, "nl_unpack32", Metric::abs, A4, Layout::none, 4e-6, 2e-6},
    {MSM_K_NL_SHADOW, "nl_shadow", Metric::abs, A1, Layout::none, 0.1, 2e-4},
    // baselines.h. VSM: the same IEEE operations (measured 0). Exponential warps: Vulkan's exp
    // within 3 + 2|x| <= 163 ulp (9.7e-6) for |x| <= 80, twice that for w² (measured 116 / 87);
    // the shadows carry it: ESM 1 - b exp(-c zf) by at most 9.7e-6 (measured 6.6e-6 / 4.8e-6),
    // EVSM amplified where zf's warp is close to the mean (1.8e-4 / 6.7e-5). log-sum-exp 4.8e-7 /
    // 1.2e-7. CSM: sin/cos of (2k - 1)πz up to 31π (basis 6.0e-8 / 6.0e-8, shadow 3.0e-7 /
    // 1.2e-7).
    {MSM_K_VSM_SHADOW, "vsm_shadow", Metric::abs, A1, Layout::none, 1e-6, 5e-7},
    {MSM_K_VSM_SHADOW_THETA2, "vsm_shadow_theta2", Metric::abs, A1, Layout::none, 1e-6, 5e-7},
    {MSM_K_ESM_MOMENT, "esm_moment", Metric::ulp, A1, Layout::none, 164, 128},
    {MSM_K_ESM_SHADOW, "esm_shadow", Metric::abs, A1, Layout::none, 2e-5, 1e-5},
    {MSM_K_ESM_LOG_MIX, "esm_log_mix", Metric::abs, A1, Layout::none, 2e-6, 1e-6},
    {MSM_K_EVSM2_MOMENTS, "evsm2_moments", Metric::ulp, A2, Layout::none, 328, 192},
    {MSM_K_EVSM2_SHADOW, "evsm2_shadow", Metric::abs, A1, Layout::none, 1e-3, 2e-4},
    {MSM_K_EVSM4_MOMENTS, "evsm4_moments", Metric::ulp, A4, Layout::none, 328, 192},
    {MSM_K_EVSM4_SHADOW, "evsm4_shadow", Metric::abs, A1, Layout::none, 1e-3, 2e-4},
    {MSM_K_CSM_BASIS, "csm_basis_texel", Metric::abs, A4, Layout::none, 1e-5, 2e-6},
    {MSM_K_CSM_SHADOW, "csm_shadow", Metric::abs, A1, Layout::none, 1e-5, 2e-6},
    {MSM_K_OVERDARKEN, "overdarken", Metric::abs, A1, Layout::none, 0, 0}, // a correctly rounded division
    // Whole reconstructions from stored texels, every storage path of four moments (the 2015 θ4
    // 16-bit ones with their D2 floor), and the soft techniques' blocker search and shadow from
    // one-texel summed-area-table queries; inputs weighted towards the edge classes (see
    // edge_pool) and ~2% non-finite ones. The inverse transforms are written out `precise`
    // (quantize.h), so both sides start from the same moments: before that, their one-ulp
    // differences moved Hausdorff θ4 16-bit by up to 0.6 near the near end and the six-moment
    // blocker shadow by 0.2. Measured over 6 seeds: technique shadows 1.6e-3 / 3.5e-5, soft4
    // 7.2e-5 / 2.1e-5, soft6 1.2e-3 / 3.7e-4 (as blocker6 and its upper variant), raise_d2 0 / 0.
    {MSM_K_TECHNIQUE_SHADOW4, "technique_shadow4", Metric::abs, A1, Layout::none, 0.01, 2e-4},
    {MSM_K_SOFT4, "soft4", Metric::abs, A3, Layout::none, 1e-3, 2e-4},
    {MSM_K_SOFT6, "soft6", Metric::abs, A3, Layout::none, 0.01, 2e-3},
    {MSM_K_RAISE_D2, "raise_d2", Metric::abs, A4, Layout::none, 1e-6, 5e-7},
    // Prefiltered scattering: the bounds of hamburger4/6 blended by β after the inverse transform
    // and the bias, so the tolerances of hamburger4_bounds and hamburger6_blend. Measured on
    // lavapipe (emulated fma): four 6.1e-5 / 3.1e-5, six 4.9e-4 / 2.4e-4.
    {MSM_K_SCATTERING4, "scattering_visibility4", Metric::abs, A1, Layout::none, 0.01, 2e-4},
    {MSM_K_SCATTERING6, "scattering_visibility6", Metric::abs, A1, Layout::none, 5e-3, 1e-3},
    // The resampling's mip level: cos, sin, a length and log2 (Vulkan: log2 within 3 ulp outside
    // [0.5, 2], 2^-21 absolute inside; cos/sin 2^-11 absolute on [-π, π], here φ in [0, 2π):
    // up to ~1e-3 in the level on such a device). Measured on lavapipe 4.2e-7 / 2.2e-7.
    {MSM_K_RESAMPLING_LOD, "rectified_resampling_lod", Metric::abs, A1, Layout::none, 2e-3, 2e-4},
    // The layer position (K − 1) log(Δ / Δ_lo) / log(Δ_hi / Δ_lo) and a layer's step over Δ_lo
    // (pow): measured 7.3e-7 / 4.6e-7 on lavapipe. Bounds from Vulkan's log (2^-21 absolute near 1)
    // times (K − 1) = 15 over the smallest span log 1.5: 3.5e-5.
    {MSM_K_TRANSMITTANCE_LAYERS, "transmittance_layers", Metric::abs, A2, Layout::none, 1e-4, 2e-5},
    // App. D.5's level: a wrap (floor), products, a min and log2 (Vulkan: 3 ulp outside [0.5, 2],
    // 2^-21 absolute inside): bounds 1e-4 / 2e-5 as the layers'. Measured on lavapipe 1.8e-7 / 1.2e-7.
    {MSM_K_PREFIX_SUM_LOD, "prefix_sum_lod", Metric::abs, A1, Layout::none, 1e-4, 2e-5},
    // The proportional β: a ratio of the bounds (a division: 2.5 ulp in Vulkan) and the epipole's
    // ramp from a dot product (slope 20 at the epipole: a few 1e-6). Bounds as the layers'. Measured
    // on lavapipe: 0 (the same operations in the same order).
    {MSM_K_SCATTERING_BETA, "scattering_beta_proportional", Metric::abs, A1, Layout::none, 1e-4, 2e-5},
    // The phase function, values from 1e-13 to 1e13 (|g| up to the largest float below 1): two dot
    // products, a division and sqrt (Vulkan: 2.5 ulp and that of inversesqrt), and the fma that
    // either side may contract: within a few ulp wherever it is evaluated, the peak included.
    // Measured on lavapipe: 0 / 0.
    {MSM_K_SCATTERING_PHASE, "scattering_phase", Metric::ulp, A1, Layout::none, 16, 8},
    // A spot light's unshadowed in-scattering (32 midpoints in ψ: angles by atan, sin, exp and the
    // phase) and its prefix-sum weight (sin, cos, exp, the phase), values up to ~1 and ~1e4
    // (relative above 1). Vulkan's sin and cos are 2^-11 absolute: bounds 2e-3 / 2e-4. Measured on
    // lavapipe: 6.6e-5 / 1.1e-5 (10 000 inputs: 32 iterations each) and 4.8e-7 / 1.2e-7.
    {MSM_K_SPOT_INSCATTERING, "spot_inscattering", Metric::abs, A1, Layout::none, 2e-3, 2e-4, 1.0, Values, 0, 0.0f,
     10000},
    {MSM_K_SPOT_PREFIX_WEIGHT, "spot_prefix_weight", Metric::abs, A1, Layout::none, 2e-3, 2e-4},
};

// The functions whose outputs are shadows, bounds or blocker depths: finite on every input,
// non-finite ones included (no NaN reaches a max(), and none comes out), on the CPU and the device.
bool finite_outputs(int id) {
  return id == MSM_K_HAMBURGER4_BOUNDS || id == MSM_K_HAUSDORFF4 || id == MSM_K_HAMBURGER6_BOUNDS ||
         id == MSM_K_HAMBURGER6_BLEND || id == MSM_K_BLOCKER4 || id == MSM_K_BLOCKER4_UPPER || id == MSM_K_BLOCKER6 ||
         id == MSM_K_BLOCKER6_UPPER || id == MSM_K_NL_SHADOW || id == MSM_K_TECHNIQUE_SHADOW4 || id == MSM_K_SOFT4 ||
         id == MSM_K_SOFT6 || id == MSM_K_SCATTERING4 || id == MSM_K_SCATTERING6;
}

const Spec& spec_of(int id) {
  for (const Spec& s : kSpecs)
    if (s.id == id) return s;
  throw std::out_of_range("no Spec for function id " + std::to_string(id));
}

// ================================ Error of one output against the other ================================

struct Field {
  int word, shift, bits;
};

std::vector<Field> fields(Layout layout) {
  switch (layout) {
  case Layout::unorm16x4: return {{0, 0, 16}, {0, 16, 16}, {1, 0, 16}, {1, 16, 16}};
  case Layout::unorm10x3: return {{0, 0, 10}, {0, 10, 10}, {0, 20, 10}};
  case Layout::nl32: return {{0, 0, 19}, {0, 19, 7}, {0, 26, 6}}; // depth pair, sqrt(v2), Ψ4
  case Layout::none: break;
  }
  return {};
}

float& channel(KernelIO& k, int i) { return i < 4 ? k.a[i] : k.b[i - 4]; }
float channel(const KernelIO& k, int i) { return i < 4 ? k.a[i] : k.b[i - 4]; }

float flush_subnormal(float x) { return std::abs(x) < std::numeric_limits<float>::min() ? 0.0f : x; }

// Distance in units in the last place (0 for +0 and -0); NaN against anything but NaN is infinite.
double ulp_distance(float g, float c) {
  if (std::isnan(g) || std::isnan(c)) return std::isnan(g) && std::isnan(c) ? 0.0 : kInf;
  auto ordered = [](float x) {
    int32_t i = std::bit_cast<int32_t>(flush_subnormal(x));
    return i < 0 ? -int64_t(i & 0x7FFFFFFF) : int64_t(i);
  };
  return double(std::abs(ordered(g) - ordered(c)));
}

// |g - c| / max(1, |c|); equal infinities (nodes at infinity) agree.
double abs_error(float g, float c) {
  if (std::isnan(g) || std::isnan(c)) return std::isnan(g) && std::isnan(c) ? 0.0 : kInf;
  if (std::isinf(g) || std::isinf(c)) return g == c ? 0.0 : kInf;
  double gd = flush_subnormal(g), cd = flush_subnormal(c);
  return std::abs(gd - cd) / std::max(1.0, std::abs(cd));
}

// Shape::Nodes: far nodes to +inf, then (node, weight) pairs sorted by node (NaN last).
KernelIO canonical(const Spec& spec, KernelIO k) {
  if (spec.shape != Shape::nodes) return k;
  std::array<std::pair<float, float>, 4> p{};
  for (int i = 0; i < spec.nodes; ++i)
    p[i] = {std::abs(k.a[i]) >= kFar ? std::numeric_limits<float>::infinity() : k.a[i], k.b[i]};
  auto before = [](std::pair<float, float> x, std::pair<float, float> y) {
    return !std::isnan(x.first) && (std::isnan(y.first) || x.first < y.first);
  };
  for (int i = 1; i < spec.nodes; ++i)
    for (int j = i; j > 0 && before(p[j], p[j - 1]); --j) std::swap(p[j], p[j - 1]);
  for (int i = 0; i < spec.nodes; ++i) k.a[i] = p[i].first, k.b[i] = p[i].second;
  return k;
}

// Error of output i (a float channel, or field i).
double error(const Spec& spec, const KernelIO& g, const KernelIO& c, int i) {
  if (spec.metric == Metric::fields) {
    Field f = fields(spec.layout)[i];
    uint32_t mask = (1u << f.bits) - 1u;
    int64_t gv = (g.u[f.word] >> f.shift) & mask, cv = (c.u[f.word] >> f.shift) & mask;
    return double(std::abs(gv - cv));
  }
  return spec.metric == Metric::ulp ? ulp_distance(channel(g, i), channel(c, i))
                                    : abs_error(channel(g, i), channel(c, i));
}

// The indices of the compared outputs.
std::vector<int> outputs(const Spec& spec) {
  std::vector<int> o;
  if (spec.metric == Metric::fields)
    for (int i = 0; i < int(fields(spec.layout).size()); ++i) o.push_back(i);
  else
    for (int i = 0; i < 8; ++i)
      if (spec.floats & (1 << i)) o.push_back(i);
  return o;
}

// Inputs whose UNORM channels (Spec::tie_steps) lie exactly on a tie, moved one float down so that
// they round down; on other inputs the identity.
KernelIO ties_rounded_down(const Spec& spec, KernelIO x) {
  for (int i = 0; i < 8; ++i) {
    float scaled = std::clamp(channel(x, i), 0.0f, 1.0f) * spec.tie_steps;
    if (scaled - std::floor(scaled) == 0.5f) channel(x, i) = std::nextafter(channel(x, i), 0.0f);
  }
  return x;
}

struct Comparison {
  double max = 0.0, p999 = 0.0;
  size_t worst = 0;   // index of the input with the largest error
  size_t nonzero = 0; // inputs with any difference
  size_t ties = 0;    // inputs where a UNORM tie rounded the other way (accepted)
};

// Per input, the largest error over the compared outputs. With Spec::tie_steps, an output may
// also equal the CPU result for its input channel rounded down at a tie (tie_cpu).
Comparison compare(const Spec& spec, const std::vector<KernelIO>& gpu, const std::vector<KernelIO>& cpu,
                   const std::vector<KernelIO>* tie_cpu = nullptr) {
  std::vector<double> errors(cpu.size());
  std::vector<int> compared = outputs(spec);
  Comparison r;
  for (size_t n = 0; n < cpu.size(); ++n) {
    KernelIO g = canonical(spec, gpu[n]), c = canonical(spec, cpu[n]);
    double e = 0.0;
    bool tie = false;
    for (int i : compared) {
      double ei = error(spec, g, c, i);
      if (ei > 0.0 && tie_cpu) {
        double ej = error(spec, g, canonical(spec, (*tie_cpu)[n]), i);
        if (ej < ei) ei = ej, tie = true;
      }
      e = std::max(e, std::isnan(ei) ? kInf : ei);
    }
    errors[n] = e;
    r.ties += tie;
    r.nonzero += e > 0.0;
    if (e > r.max) r.max = e, r.worst = n;
  }
  std::sort(errors.begin(), errors.end());
  r.p999 = errors.empty() ? 0.0 : errors[size_t(0.999 * double(errors.size() - 1))];
  return r;
}

double differing(const Comparison& c, size_t n) { return double(c.nonzero) / double(std::max<size_t>(n, 1)); }

bool within(const Spec& spec, const Comparison& c, size_t n) {
  return c.max <= spec.max_tol && c.p999 <= spec.p999_tol && differing(c, n) <= spec.differ_tol;
}

// ================================ Inputs ================================

// Moments of one random depth distribution on [-1,1] (and the same depths mapped to [0,1],
// zu = (z + 1) / 2), in double, for every representation the functions read.
struct Texel {
  std::array<double, 7> s{};     // power moments b0..b6, [-1,1] depth
  std::array<double, 5> u{};     // power moments b0..b4, [0,1] depth
  std::array<double, 4> trig{};  // E(sin 2πzu, cos 2πzu, sin 4πzu, cos 4πzu)
  double esm80 = 0.0;            // E exp(80 zu)
  std::array<double, 2> pos40{}; // E(w, w²), w = exp(40 z)
  std::array<double, 2> pos5{};  // the same for c+ = 5.54
  std::array<double, 2> neg5{};  // E(w, w²), w = -exp(-5.54 z)
  std::array<double, 8> csm{};   // E(sin c_k zu, cos c_k zu), c_k = (2k - 1)π, k = 1..4
  double surface = 0.0;          // the depth of largest weight ([-1,1]): a flat receiver there

  // Rounded to float: b1..b4 for [-1,1] or [0,1] depth, b1..b6 for [-1,1].
  vec4 signed4() const { return vec4(float(s[1]), float(s[2]), float(s[3]), float(s[4])); }
  vec4 unit4() const { return vec4(float(u[1]), float(u[2]), float(u[3]), float(u[4])); }
  Moments6 signed6() const {
    return Moments6(vec3(float(s[1]), float(s[3]), float(s[5])), vec3(float(s[2]), float(s[4]), float(s[6])));
  }
  float unit_surface() const { return float(0.5 * surface + 0.5); }
};

Texel make_texel(const test::Distribution& d) {
  Texel t;
  double heaviest = -1.0;
  for (size_t i = 0; i < d.z.size(); ++i) {
    double z = d.z[i], w = d.w[i], zu = 0.5 * z + 0.5;
    for (double j = 0, p = w; j < 7; ++j, p *= z) t.s[size_t(j)] += p;
    for (double j = 0, p = w; j < 5; ++j, p *= zu) t.u[size_t(j)] += p;
    double a = 2.0 * std::numbers::pi * zu;
    t.trig[0] += w * std::sin(a), t.trig[1] += w * std::cos(a);
    t.trig[2] += w * std::sin(2.0 * a), t.trig[3] += w * std::cos(2.0 * a);
    t.esm80 += w * std::exp(80.0 * zu);
    double p40 = std::exp(40.0 * z), p5 = std::exp(double(MSM_EVSM_C_64BIT) * z), n5 = -1.0 / p5;
    t.pos40[0] += w * p40, t.pos40[1] += w * p40 * p40;
    t.pos5[0] += w * p5, t.pos5[1] += w * p5 * p5;
    t.neg5[0] += w * n5, t.neg5[1] += w * n5 * n5;
    for (int k = 1; k <= 4; ++k) {
      double ck = double(2 * k - 1) * std::numbers::pi;
      t.csm[2 * k - 2] += w * std::sin(ck * zu), t.csm[2 * k - 1] += w * std::cos(ck * zu);
    }
    if (w > heaviest) heaviest = w, t.surface = z;
  }
  return t;
}

// A fixed pool of texels shared by all functions: single depths (the most common texel: a flat
// receiver), two depths, 1-8 Diracs and continuous distributions, plus the edges of the range.
const std::vector<Texel>& texel_pool() {
  static const std::vector<Texel> pool = [] {
    std::mt19937_64 rng(20240607);
    std::vector<Texel> p;
    for (double z : {-1.0, 0.0, 1.0, -0.5, 0.5}) p.push_back(make_texel(test::Distribution{{z}, {1.0}}));
    p.push_back(make_texel(test::Distribution{{-1.0, 1.0}, {0.5, 0.5}})); // the first 6: see make_inputs
    std::uniform_int_distribution<int> kind(0, 19);
    while (p.size() < 40000) {
      int k = kind(rng);
      test::Distribution d = k < 4   ? test::random_diracs(rng, 1, -1.0, 1.0)
                             : k < 7 ? test::random_diracs(rng, 2, -1.0, 1.0)
                                     : test::random_distribution(rng, -1.0, 1.0);
      p.push_back(make_texel(d));
    }
    return p;
  }();
  return pool;
}

// Issue 19's edge classes, for the reconstructions (edges_test holds them against the oracles):
// an occluder at the near end alone or beside a receiver (the receiver first, so that it is the
// texel's surface), depths at both ends with or without a third, and clusters of 2-5 depths
// 1e-6..1e-3 apart (the receiver on the heaviest).
const std::vector<Texel>& edge_pool() {
  static const std::vector<Texel> pool = [] {
    std::mt19937_64 rng(20240619);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Texel> p;
    while (p.size() < 4000) {
      test::Distribution d;
      switch (p.size() % 4) {
      case 0: d = {{-1.0 + 2.0 * u(rng), -1.0}, {0.5, 0.5}}; break;
      case 1: d = {{-1.0}, {1.0}}; break;
      case 2:
        d = {{-1.0, 1.0}, {0.05 + u(rng), 0.05 + u(rng)}};
        if (u(rng) < 0.5) d.z.push_back(-1.0 + 2.0 * u(rng)), d.w.push_back(0.05 + u(rng));
        break;
      default: {
        double centre = -1.0 + 2.0 * u(rng), spacing = std::pow(10.0, -6.0 + 3.0 * u(rng));
        for (int i = 0, n = 2 + int(u(rng) * 4.0) % 4; i < n; ++i)
          d.z.push_back(std::min(1.0, centre + i * spacing)), d.w.push_back(0.1 + u(rng));
      }
      }
      double sum = 0.0;
      for (double w : d.w) sum += w;
      for (double& w : d.w) w /= sum;
      p.push_back(make_texel(d));
    }
    return p;
  }();
  return pool;
}

bool edge_function(int id) { return finite_outputs(id) || id == MSM_K_HAMBURGER4_CANONICAL || id == MSM_K_RAISE_D2; }

class Inputs {
 public:
  explicit Inputs(uint64_t seed) : rng_(seed) {}

  float uni(float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng_); }
  bool chance(double p) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < p; }
  // A stored 16-bit texel: half the time the quantized encoding of a valid vector, else any.
  vec4 unorm16_or_any(vec4 encoding) {
    return chance(0.5) ? msm_quantize_unorm16(encoding) : vec4(uni(0, 1), uni(0, 1), uni(0, 1), uni(0, 1));
  }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  uint32_t word() { return uint32_t(rng_()); }
  float log_uniform(float lo, float hi) { return std::exp(uni(std::log(lo), std::log(hi))); }
  const Texel& texel() {
    const std::vector<Texel>& pool = texel_pool();
    return pool[size_t(rng_() % pool.size())];
  }
  const Texel& edge_texel() {
    const std::vector<Texel>& pool = edge_pool();
    return pool[size_t(rng_() % pool.size())];
  }
  // One of the values that broke reconstructions: NaN, ±inf, huge.
  float special() {
    const float values[] = {std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            1e30f,
                            -1e30f,
                            3e38f};
    return values[integer(0, 5)];
  }
  // A fragment depth for a texel whose surface lies at 'surface' in [lo, hi]: anywhere around
  // the range, exactly on the surface (the flat receiver), or just in front of or behind it.
  float receiver(float surface, float lo, float hi) {
    int k = integer(0, 9);
    float margin = 0.1f * (hi - lo);
    if (k < 4) return uni(lo - margin, hi + margin);
    if (k < 6) return surface;
    if (k < 7) return std::nextafter(surface, chance(0.5) ? hi + 1.0f : lo - 1.0f); // one ulp off
    return surface + (chance(0.5) ? 1.0f : -1.0f) * log_uniform(1e-5f, 1e-2f) * (hi - lo);
  }

  // Four moments as a 4MSM shader reads them, in one of the representations of bias.h, biased
  // for it. Depth range [lo, hi] of that convention and the receiver on its surface.
  struct Moments4 {
    vec4 b;
    float lo, hi, surface;
  };
  Moments4 moments4(const Texel& t) {
    int k = integer(0, 9);
    bool unit = k >= 6;
    vec4 b = unit ? t.unit4() : t.signed4();
    int rep = MSM_REP_SIGNED_FLOAT;
    if (k == 4 || k == 5) { // 64-bit Θ4* storage
      b = msm_theta4_star_inverse(msm_quantize_unorm16(msm_theta4_star(b)));
      rep = MSM_REP_SIGNED_THETA4;
    } else if (k == 6 || k == 7) {
      rep = MSM_REP_UNIT_FLOAT;
    } else if (k >= 8) { // 64-bit θ4 storage (2015)
      b = msm_theta4_inverse(msm_quantize_unorm16(msm_theta4(b)));
      rep = MSM_REP_UNIT_THETA4;
    }
    float surface = float(unit ? 0.5 * t.surface + 0.5 : t.surface);
    return Moments4{msm_apply_bias(b, msm_moment_bias(rep)), unit ? 0.0f : -1.0f, 1.0f, surface};
  }
  // Six moments ([-1,1] depth), in float, 16-bit or 10-bit Θ6* storage, biased for it.
  Moments6 moments6(const Texel& t) {
    Moments6 b = t.signed6();
    int k = integer(0, 9);
    if (k < 7) return msm_apply_bias6(b, msm_moment_bias6(MSM_REP6_FLOAT));
    if (k < 9)
      return msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm16(msm_theta6_star(b))),
                             msm_moment_bias6(MSM_REP6_UNORM16));
    return msm_apply_bias6(msm_theta6_star_inverse(msm_quantize_unorm10(msm_theta6_star(b))),
                           msm_moment_bias6(MSM_REP6_UNORM10));
  }
  // Φ of the biased float moments of a texel, as stored: unquantized, or through 64 or 32 bits.
  NonLinearMoments nonlinear(const Texel& t) {
    vec4 b = t.signed4();
    NonLinearMoments m = msm_nl_from_filtered(b);
    int k = integer(0, 2);
    return k == 0 ? m : k == 1 ? msm_nl_quantize64(m) : msm_nl_quantize32(m);
  }
  // Arbitrary (y1 <= y2, v2, ξ4) in the ranges Φ produces.
  NonLinearMoments random_nonlinear() {
    float y1 = uni(-1.0f, 1.0f), y2 = uni(-1.0f, 1.0f);
    float xi4 = chance(0.1) ? 0.0f : log_uniform(1e-9f, 0.3f);
    return NonLinearMoments(std::min(y1, y2), std::max(y1, y2), chance(0.1) ? float(integer(0, 1)) : uni(0.0f, 1.0f),
                            xi4);
  }
  // A value to be stored in UNORM: mostly in [0,1], some outside (clamped), some exactly on a
  // rounding tie k + 1/2 of v (2^n - 1) where float can hold it, some exactly representable.
  float unorm_value(float steps) {
    int k = integer(0, 9);
    if (k == 0) return uni(-0.2f, 1.2f);
    float q = float(integer(0, int(steps) - 1));
    if (k == 1) return (q + 0.5f) / steps;
    if (k == 2) return q / steps;
    return uni(0.0f, 1.0f);
  }
  // Polynomial coefficients (ascending powers) with real roots in [-1,1] (some pairs close
  // together, some roots far away) and a random scale. Degree 2 or 3.
  vec4 polynomial(int degree) {
    double r[3] = {uni(-1.0f, 1.0f), uni(-1.0f, 1.0f), uni(-1.0f, 1.0f)};
    int k = integer(0, 9);
    if (k == 0) r[degree - 1] = (chance(0.5) ? 1.0 : -1.0) * log_uniform(10.0f, 1e6f);
    if (k == 1) r[1] = r[0] + log_uniform(1e-4f, 1e-2f);
    double s = log_uniform(1e-3f, 1e3f) * (chance(0.5) ? 1.0 : -1.0);
    if (degree == 2) return vec4(float(s * r[0] * r[1]), float(-s * (r[0] + r[1])), float(s), 0.0f);
    double e1 = r[0] + r[1] + r[2], e2 = r[0] * r[1] + r[0] * r[2] + r[1] * r[2], e3 = r[0] * r[1] * r[2];
    return vec4(float(-s * e3), float(s * e2), float(-s * e1), float(s)); // s (z - r0)(z - r1)(z - r2)
  }

 private:
  std::mt19937_64 rng_;
};

uint32_t bits(float f) { return std::bit_cast<uint32_t>(f); }

// The seed of a function's inputs: FNV-1a of its name (stable when ids are renumbered), plus
// MSM_GPU_MATH_SEED if set (to look at other inputs).
uint64_t seed(const char* name) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const char* c = name; *c; ++c) h = (h ^ uint64_t(uint8_t(*c))) * 0x100000001b3ull;
  const char* extra = std::getenv("MSM_GPU_MATH_SEED");
  return h + (extra ? std::strtoull(extra, nullptr, 10) : 0u);
}

// 'count' inputs for function 'id', meaningful for it. The first 60 take the fixed texels at the
// start of the pool (single depths at -1, 0, 1, ...) in turn; then random ones. Long on purpose:
// one case per kernel function, a table read by function id, each case a few lines.
std::vector<KernelIO> make_inputs(int id, int count) {
  Inputs g(seed(spec_of(id).name));
  std::vector<KernelIO> in(count);
  for (int n = 0; n < count; ++n) {
    KernelIO& x = in[n];
    x = KernelIO{};
    const Texel& t = n < 60 ? texel_pool()[n % 6] : (edge_function(id) && g.chance(0.3)) ? g.edge_texel() : g.texel();
    switch (id) {
    case MSM_K_MOMENTS4:
    case MSM_K_MOMENTS6:
    case MSM_K_EVSM2_MOMENTS:
    case MSM_K_EVSM4_MOMENTS: {
      float z = g.chance(0.05) ? float(g.integer(-2, 2)) * 0.5f : g.uni(-1.0f, 1.0f);
      bool wide = g.chance(0.5); // 32-bit float channels (c+ = 40) or 16-bit (5.54)
      x.a = vec4(z, wide ? MSM_EVSM_C_POS_128BIT : MSM_EVSM_C_64BIT, MSM_EVSM_C_NEG_128BIT, 0.0f);
      break;
    }
    case MSM_K_TRIG_MOMENTS:
    case MSM_K_CSM_BASIS:
      x.a[0] = g.chance(0.05) ? float(g.integer(0, 4)) * 0.25f : g.uni(0.0f, 1.0f);
      x.u[0] = uint32_t(g.integer(0, MSM_CSM_MAX_TEXELS - 1));
      break;
    case MSM_K_UNIT_TO_SIGNED:
    case MSM_K_THETA4: x.a = t.unit4(); break;
    case MSM_K_THETA4_INVERSE: x.a = g.unorm16_or_any(msm_theta4(t.unit4())); break;
    case MSM_K_THETA4_STAR:
    case MSM_K_TWO_DEPTHS:
    case MSM_K_NL_FROM_MOMENTS: {
      vec4 b = t.signed4();
      // Φ and the two depths get biased moments (their precondition) and some unbiased ones.
      x.a = (id == MSM_K_THETA4_STAR || g.chance(0.1)) ? b : msm_apply_bias(b, msm_moment_bias(MSM_REP_SIGNED_FLOAT));
      break;
    }
    case MSM_K_THETA4_STAR_INVERSE: x.a = g.unorm16_or_any(msm_theta4_star(t.signed4())); break;
    case MSM_K_THETA6_STAR:
    case MSM_K_APPLY_BIAS6:
      x.a = vec4(t.signed6().odd, 0.0f);
      x.b = vec4(t.signed6().even, 0.0f);
      x.u[0] = uint32_t(g.integer(MSM_REP6_UNORM10, MSM_REP6_FLOAT));
      break;
    case MSM_K_THETA6_STAR_INVERSE:
    case MSM_K_QUANTIZE6_UNORM16:
    case MSM_K_QUANTIZE6_UNORM10: {
      Moments6 q = msm_theta6_star(t.signed6());
      if (g.chance(0.3))
        q = Moments6(vec3(g.uni(0, 1), g.uni(0, 1), g.uni(0, 1)), vec3(g.uni(0, 1), g.uni(0, 1), g.uni(0, 1)));
      x.a = vec4(q.odd, 0.0f);
      x.b = vec4(q.even, 0.0f);
      break;
    }
    case MSM_K_THETA2: x.a = vec4(t.unit4()[0], t.unit4()[1], 0.0f, 0.0f); break;
    case MSM_K_THETA2_INVERSE: x.a = vec4(g.uni(0, 1), g.uni(0, 1), 0.0f, 0.0f); break;
    case MSM_K_PACK_UNORM16:
      x.a = vec4(g.unorm_value(65535.0f), g.unorm_value(65535.0f), g.unorm_value(65535.0f), g.unorm_value(65535.0f));
      break;
    case MSM_K_PACK_UNORM10:
      x.a = vec4(g.unorm_value(1023.0f), g.unorm_value(1023.0f), g.unorm_value(1023.0f), 0.0f);
      break;
    case MSM_K_UNPACK_UNORM16:
    case MSM_K_UNPACK_UNORM10:
    case MSM_K_NL_UNPACK64:
    case MSM_K_NL_UNPACK32: x.u = uvec4(g.word(), g.word(), 0u, 0u); break;
    case MSM_K_APPLY_BIAS: {
      x.u[0] = uint32_t(g.integer(MSM_REP_UNIT_FLOAT, MSM_REP_SAT_INT32));
      bool unit = x.u[0] <= uint32_t(MSM_REP_UNIT_THETA4);
      x.a = unit ? t.unit4() : t.signed4();
      break;
    }
    case MSM_K_SOLVE_QUADRATIC: // and some with a root at infinity (c2 = 0) or complex roots
      x.a = g.polynomial(2);
      if (g.chance(0.1)) x.a[2] = 0.0f;
      if (g.chance(0.1)) x.a = vec4(g.uni(-1, 1), g.uni(-1, 1), g.uni(-1, 1), 0.0f);
      break;
    case MSM_K_CUBIC_ROOTS: x.a = g.polynomial(3); break;
    case MSM_K_HAMBURGER4_BOUNDS:
    case MSM_K_HAMBURGER4_CANONICAL:
    case MSM_K_HAUSDORFF4:
    case MSM_K_BLOCKER4:
    case MSM_K_BLOCKER4_UPPER: {
      Inputs::Moments4 m = g.moments4(t);
      float delta1 = g.log_uniform(1e-4f, 1e-2f);
      x.a = m.b;
      x.b = vec4(g.receiver(m.surface, m.lo, m.hi), id == MSM_K_HAUSDORFF4 ? m.lo : delta1,
                 id == MSM_K_HAUSDORFF4 ? m.hi : delta1 * g.log_uniform(1.0f, 100.0f), 0.0f);
      break;
    }
    case MSM_K_HAMBURGER6_BOUNDS:
    case MSM_K_HAMBURGER6_BLEND:
    case MSM_K_HAMBURGER6_CANONICAL:
    case MSM_K_BLOCKER6:
    case MSM_K_BLOCKER6_UPPER: {
      Moments6 b = g.moments6(t);
      float delta1 = g.log_uniform(1e-4f, 1e-2f);
      x.a = vec4(b.odd, g.receiver(float(t.surface), -1.0f, 1.0f));
      x.b = vec4(b.even, g.uni(0.0f, 1.0f));
      x.u = uvec4(bits(delta1), bits(delta1 * g.log_uniform(1.0f, 100.0f)), 0u, 0u);
      break;
    }
    case MSM_K_TRIG_BOUNDS:
      x.a = msm_trig_bias(vec4(float(t.trig[0]), float(t.trig[1]), float(t.trig[2]), float(t.trig[3])));
      x.b[0] = g.receiver(t.unit_surface(), 0.0f, 1.0f);
      break;
    case MSM_K_NL_MOMENTS_FROM:
    case MSM_K_NL_PACK64:
    case MSM_K_NL_PACK32:
    case MSM_K_NL_SHADOW: {
      NonLinearMoments m = g.chance(0.7) ? g.nonlinear(t) : g.random_nonlinear();
      x.a = vec4(m.y1, m.y2, m.v2, m.xi4);
      x.b[0] = g.receiver(float(t.surface), -1.0f, 1.0f);
      break;
    }
    case MSM_K_VSM_SHADOW:
    case MSM_K_VSM_SHADOW_THETA2: {
      vec2 b = vec2(t.unit4());
      if (id == MSM_K_VSM_SHADOW_THETA2) b = msm_quantize_unorm16x2(msm_theta2(b));
      x.a = vec4(b, g.receiver(t.unit_surface(), 0.0f, 1.0f), 0.0f);
      break;
    }
    case MSM_K_ESM_MOMENT: {
      bool unit = g.chance(0.5); // c = 80 on [0,1] depth, or c = 40 on [-1,1]
      x.a = vec4(unit ? g.uni(0.0f, 1.0f) : g.uni(-1.0f, 1.0f), unit ? MSM_ESM_C_DEFAULT : 40.0f, 0.0f, 0.0f);
      break;
    }
    case MSM_K_ESM_SHADOW:
      // zf in [0,1]: beyond it exp(-80 zf) is subnormal (flushed to 0 on the device).
      x.a = vec4(float(t.esm80), std::clamp(g.receiver(t.unit_surface(), 0.0f, 1.0f), 0.0f, 1.0f), MSM_ESM_C_DEFAULT,
                 0.0f);
      break;
    case MSM_K_ESM_LOG_MIX: {
      float la = g.uni(-80.0f, 80.0f);
      x.a = vec4(la, std::clamp(la + g.uni(-87.0f, 87.0f), -80.0f, 80.0f), g.uni(0.0f, 1.0f), 0.0f);
      break;
    }
    case MSM_K_EVSM2_SHADOW:
    case MSM_K_EVSM4_SHADOW: {
      // 32-bit float channels (c+ = 40, c- = 5.54) or 16-bit ones (5.54, 5.54, half storage).
      bool wide = g.chance(0.5);
      const std::array<double, 2>& pos = wide ? t.pos40 : t.pos5;
      vec4 b = vec4(float(pos[0]), float(pos[1]), float(t.neg5[0]), float(t.neg5[1]));
      if (!wide) b = msm_quantize_half4(b);
      float zf = g.receiver(float(t.surface), -1.0f, 1.0f);
      float c_pos = wide ? MSM_EVSM_C_POS_128BIT : MSM_EVSM_C_64BIT;
      float min_variance = wide ? MSM_EVSM_MIN_VARIANCE_FLOAT : MSM_EVSM_MIN_VARIANCE_HALF;
      x.a = b;
      x.b = id == MSM_K_EVSM2_SHADOW ? vec4(zf, c_pos, min_variance, 0.0f)
                                     : vec4(zf, c_pos, MSM_EVSM_C_NEG_128BIT, min_variance);
      break;
    }
    case MSM_K_CSM_SHADOW: {
      int terms = g.integer(1, 4);
      for (int i = 0; i < 4; ++i) {
        x.a[i] = i < 2 * terms ? float(t.csm[i]) : 0.0f;
        x.b[i] = 4 + i < 2 * terms ? float(t.csm[4 + i]) : 0.0f;
      }
      bool plain = g.chance(0.3);
      CsmParams p = plain ? msm_csm_plain_params(terms) : msm_csm_default_params();
      x.u = uvec4(uint32_t(terms), bits(p.damping), bits(p.scale), bits(g.receiver(t.unit_surface(), 0.0f, 1.0f)));
      break;
    }
    case MSM_K_OVERDARKEN:
      x.a = vec4(g.chance(0.1) ? float(g.integer(0, 1)) : g.uni(0.0f, 1.0f),
                 g.chance(0.5) ? MSM_OVERDARKEN_DEFAULT : g.uni(0.5f, 1.0f), 0.0f, 0.0f);
      break;
    case MSM_K_FMA: { // the cancelling differences of the Hankel pivots: b2 - b1 b1, b3 - b1 b2
      vec4 b = g.moments4(t).b;
      int k = g.integer(0, 2);
      x.a = k == 0   ? vec4(-b[0], b[0], b[1], 0.0f)
            : k == 1 ? vec4(-b[0], b[1], b[2], 0.0f)
                     : vec4(g.uni(-2, 2), g.uni(-2, 2), g.uni(-2, 2), 0.0f);
      break;
    }
    case MSM_K_NL_PSI4: // ξ4 over its range, below its floor and above its ceiling
      x.a[0] = g.chance(0.05) ? 0.0f : g.log_uniform(1e-8f, 0.5f);
      break;
    case MSM_K_NL_PSI4_INVERSE: // Ψ4 in [0,1], its 6-bit values among them
      x.a[0] = g.chance(0.2) ? msm_nl_psi4_decode6(uint32_t(g.integer(0, 63))) : g.uni(0.0f, 1.0f);
      break;
    case MSM_K_SATURATE: x.a[0] = g.chance(0.1) ? float(g.integer(-1, 2)) : g.uni(-0.5f, 1.5f); break;
    case MSM_K_TECHNIQUE_SHADOW4: {
      int tech = g.integer(MSM_TECH_HAMBURGER_128_UNIT, MSM_TECH_HAUSDORFF_64);
      bool unit = tech == MSM_TECH_HAMBURGER_128_UNIT || tech == MSM_TECH_HAUSDORFF_128_UNIT ||
                  tech == MSM_TECH_HAMBURGER_64_THETA4 || tech == MSM_TECH_HAUSDORFF_64_THETA4;
      vec4 b = unit ? t.unit4() : t.signed4();
      if (tech == MSM_TECH_HAMBURGER_64_THETA4 || tech == MSM_TECH_HAUSDORFF_64_THETA4)
        b = msm_quantize_unorm16(msm_theta4(b));
      if (tech == MSM_TECH_HAMBURGER_64 || tech == MSM_TECH_HAUSDORFF_64) b = msm_quantize_unorm16(msm_theta4_star(b));
      x.a = b;
      x.b[0] = g.receiver(t.unit_surface(), 0.0f, 1.0f);
      x.u[0] = uint32_t(tech);
      break;
    }
    case MSM_K_SOFT4:
    case MSM_K_SOFT6: {
      uint scale = msm_sat_scale(27 * 27);
      float zf = g.receiver(float(t.surface), -1.0f, 1.0f), bias = g.chance(0.5) ? 0.0f : 1e-3f;
      if (id == MSM_K_SOFT4) {
        x.a = msm_sat_rect_average(msm_sat_quantize(msm_theta4_star(t.signed4()), scale), 1, scale);
        x.b = vec4(zf, bias, 0.0f, 0.0f);
      } else {
        Moments6 q = msm_sat_rect_average6(msm_sat_quantize6(msm_theta6_star(t.signed6()), scale), 1, scale);
        x.a = vec4(q.odd, zf);
        x.b = vec4(q.even, bias);
      }
      x.u[0] = uint32_t(g.integer(0, 1));
      x.u[1] = scale;
      break;
    }
    case MSM_K_SCATTERING4: {
      // A prefix-summed texel as the lookup sees it: 16-bit Θ4* or float moments.
      const bool theta = g.chance(0.5);
      x.a = theta ? msm_quantize_unorm16(msm_theta4_star(t.signed4())) : t.signed4();
      x.b = vec4(g.receiver(float(t.surface), -1.0f, 1.0f), g.uni(0.0f, 1.0f), 0.0f, 0.0f);
      x.u[0] = uint32_t(theta ? MSM_REP_SIGNED_THETA4 : MSM_REP_SIGNED_FLOAT);
      break;
    }
    case MSM_K_SCATTERING6: {
      const int rep = g.integer(MSM_REP6_UNORM10, MSM_REP6_FLOAT);
      Moments6 q = msm_theta6_star(t.signed6());
      if (rep == MSM_REP6_UNORM10) q = msm_quantize_unorm10(q);
      if (rep == MSM_REP6_UNORM16) q = msm_quantize_unorm16(q);
      x.a = vec4(q.odd, g.receiver(float(t.surface), -1.0f, 1.0f));
      x.b = vec4(q.even, g.uni(0.0f, 1.0f));
      x.u[0] = uint32_t(rep);
      break;
    }
    case MSM_K_RESAMPLING_LOD: {
      // A texel of a 256²..4096² rectified map over r_max up to 1000, the shadow map 1..64 texels
      // per unit in any orientation (a rotation and scale, as an orthographic light's).
      const float width = float(1 << g.integer(8, 12)), r_max = g.log_uniform(1.0f, 1000.0f);
      const float phi_span = g.chance(0.5) ? MSM_TWO_PI : g.uni(0.01f, 3.0f);
      x.a = vec4(g.uni(0.0f, r_max), g.uni(0.0f, MSM_TWO_PI), r_max / width, phi_span / width);
      const float scale = g.log_uniform(1.0f, 64.0f), angle = g.uni(0.0f, MSM_TWO_PI);
      const float sx = g.chance(0.5) ? scale : -scale; // either handedness
      x.b = vec4(sx * std::cos(angle), scale * std::sin(angle), -sx * std::sin(angle), scale * std::cos(angle));
      break;
    }
    case MSM_K_PREFIX_SUM_LOD: {
      // Derivatives of u and v from a hundredth of a texel to the whole map, either sign, in a
      // 256..4096-texel map; v across the seam (|dv| near 1) at times; φ a full circle or not.
      const auto derivative = [&] { return (g.chance(0.5) ? -1.0f : 1.0f) * g.log_uniform(1e-5f, 1.0f); };
      x.a = vec4(derivative(), derivative(), derivative(), g.chance(0.2) ? g.uni(-1.0f, 1.0f) : derivative());
      x.b = vec4(float(1 << g.integer(8, 12)), float(1 << g.integer(8, 12)), g.chance(0.5) ? 1.0f : 0.0f, 0.0f);
      break;
    }
    case MSM_K_SCATTERING_BETA: {
      // Shadow bounds lower <= upper in [0, 1] (at times equal, at times a bound at 0 or 1), a
      // light direction and a view direction, a fifth of them within 40° of the epipole.
      float lower = g.chance(0.1) ? 0.0f : g.uni(0.0f, 1.0f), upper = g.chance(0.1) ? 1.0f : g.uni(lower, 1.0f);
      if (g.chance(0.05)) upper = lower;
      const auto unit = [&] {
        glm::vec3 d(g.uni(-1.0f, 1.0f), g.uni(-1.0f, 1.0f), g.uni(-1.0f, 1.0f));
        return glm::length(d) > 1e-3f ? glm::normalize(d) : glm::vec3(0.0f, 1.0f, 0.0f);
      };
      const glm::vec3 light = unit();
      glm::vec3 view = unit();
      if (g.chance(0.2))
        view = glm::normalize(light + g.uni(0.0f, 0.7f) * unit()); // the epipole: view towards the light
      x.a = vec4(lower, upper, view.x, view.y);
      x.b = vec4(view.z, light.x, light.y, light.z);
      break;
    }
    case MSM_K_SCATTERING_PHASE: {
      // g anywhere in (-1, 1), a third of them within 1e-7..1e-1 of ±1; view directions a third
      // within 1e-7..1 rad of the light (the forward peak), a tenth of the opposite (the backward).
      const auto unit = [&] {
        glm::vec3 d(g.uni(-1.0f, 1.0f), g.uni(-1.0f, 1.0f), g.uni(-1.0f, 1.0f));
        return glm::length(d) > 1e-3f ? glm::normalize(d) : glm::vec3(0.0f, 1.0f, 0.0f);
      };
      const float sign = g.chance(0.5) ? 1.0f : -1.0f;
      const float asymmetry = g.chance(0.33) ? sign * (1.0f - g.log_uniform(1e-7f, 0.1f)) : g.uni(-0.999f, 0.999f);
      const glm::vec3 light = unit();
      glm::vec3 view = unit();
      if (g.chance(0.33))
        view = glm::normalize(light + g.log_uniform(1e-7f, 1.0f) * unit());
      else if (g.chance(0.15))
        view = glm::normalize(-light + g.log_uniform(1e-7f, 1.0f) * unit());
      x.a = vec4(light, asymmetry);
      x.b = vec4(view, 0.0f);
      break;
    }
    case MSM_K_SPOT_INSCATTERING: {
      // A camera anywhere within 4 m of the light's foot, a ray towards a point of the cone at least
      // 0.1 m below the light (at times of the medium beside the cone), ending before or past it; g
      // anywhere in (-0.95, 0.95); at times a camera straight below the light or a ray of no length.
      // (A ray within millimetres of the light scatters ∝ 1 / h, h = d sin γ, and float's γ of two
      // nearly parallel directions is good to 1e-7 / γ relative on either side: 1.6% apart at
      // γ = 3e-4, measured, which is the input's conditioning, not the function's.)
      const glm::vec3 camera(g.uni(-4.0f, 4.0f), g.uni(0.0f, 3.0f), g.uni(-4.0f, 4.0f));
      const float height = g.uni(0.0f, 1.9f), radius = (2.0f - height) * 0.577f * g.uni(0.0f, 1.3f);
      const float angle = g.uni(0.0f, MSM_TWO_PI);
      const glm::vec3 target(radius * std::cos(angle), height, radius * std::sin(angle));
      const glm::vec3 eye = g.chance(0.05) ? glm::vec3(0.0f, g.uni(0.0f, 1.9f), 0.0f) : camera;
      const glm::vec3 d = target - eye;
      const glm::vec3 view = glm::length(d) > 1e-3f ? glm::normalize(d) : glm::vec3(0.0f, -1.0f, 0.0f);
      const float s = g.chance(0.03) ? 0.0f : glm::length(d) * g.uni(0.3f, 2.0f);
      x.a = vec4(eye, s);
      x.b = vec4(view, g.uni(-0.95f, 0.95f));
      break;
    }
    case MSM_K_SPOT_PREFIX_WEIGHT: {
      // A camera 0.1..100 from the light, any ψ and γ (at times ψ + γ past π: rays that never meet),
      // σt over four decades, g anywhere in (-0.99, 0.99), a cone factor in [0, 1].
      x.a = vec4(g.log_uniform(0.1f, 100.0f), g.uni(0.0f, MSM_PI), g.uni(0.0f, MSM_PI), g.log_uniform(1e-3f, 10.0f));
      x.b = vec4(g.uni(-0.99f, 0.99f), g.uni(0.0f, 1.0f), 0.0f, 0.0f);
      break;
    }
    case MSM_K_TRANSMITTANCE_LAYERS: {
      // A range of up to four decades of steps (the epipole in view), a step anywhere in and around
      // it, K = 1..16; both ends equal at times (a clamped range).
      const float lo = g.log_uniform(1e-3f, 10.0f), hi = g.chance(0.05) ? lo : lo * g.log_uniform(1.5f, 1e4f);
      x.a = vec4(lo, hi, g.log_uniform(0.5f * lo, 2.0f * hi), float(g.integer(1, 16)));
      break;
    }
    case MSM_K_RAISE_D2:
      x.a = g.moments4(t).b;
      x.b[0] = g.log_uniform(1e-8f, 1e-5f);
      break;
    default: ADD_FAILURE() << "no inputs for function id " << id;
    }
    // Non-finite and huge inputs for the reconstructions: one moment or the receiver.
    if (finite_outputs(id) && n >= 60 && g.chance(0.02)) {
      int k = g.integer(0, 4);
      if (k < 4)
        x.a[k] = g.special();
      else if (id == MSM_K_HAMBURGER6_BOUNDS || id == MSM_K_HAMBURGER6_BLEND || id == MSM_K_BLOCKER6 ||
               id == MSM_K_BLOCKER6_UPPER || id == MSM_K_SOFT6 || id == MSM_K_SCATTERING6)
        x.a[3] = g.special();
      else if (id != MSM_K_TECHNIQUE_SHADOW4)
        x.b[0] = g.special();
    }
  }
  // Fixed cases. Six moments: a single depth (-0.924, biased float moments) far in front of the
  // receiver (0.22), where two roots of the canonical representation are so close that float
  // may round them to one value (the CPU build does), making the divided differences 0/0.
  if (id == MSM_K_HAMBURGER6_BOUNDS || id == MSM_K_HAMBURGER6_BLEND || id == MSM_K_HAMBURGER6_CANONICAL ||
      id == MSM_K_BLOCKER6 || id == MSM_K_BLOCKER6_UPPER)
    in.push_back(KernelIO{vec4(-0.924062729f, -0.789057732f, -0.673776805f, 0.220052481f),
                          vec4(0.853899062f, 0.72914499f, 0.622617662f, 0.848965585f),
                          uvec4(bits(1e-3f), bits(1e-2f), 0u, 0u)});
  return in;
}

std::vector<KernelIO> run_on_cpu(int id, const std::vector<KernelIO>& in) {
  std::vector<KernelIO> out(in.size());
  for (size_t i = 0; i < in.size(); ++i) out[i] = msm_test_kernel(id, in[i]);
  return out;
}

// The CPU results with UNORM ties rounded down (Spec::tie_steps), or null.
std::unique_ptr<std::vector<KernelIO>> run_on_cpu_ties_down(const Spec& spec, const std::vector<KernelIO>& in) {
  if (spec.tie_steps == 0.0f) return nullptr;
  std::vector<KernelIO> moved(in.size());
  for (size_t i = 0; i < in.size(); ++i) moved[i] = ties_rounded_down(spec, in[i]);
  return std::make_unique<std::vector<KernelIO>>(run_on_cpu(spec.id, moved));
}

std::string describe(const KernelIO& k) {
  char s[512];
  std::snprintf(s, sizeof s, "a=(%.9g, %.9g, %.9g, %.9g) b=(%.9g, %.9g, %.9g, %.9g) u=(0x%08x, 0x%08x, 0x%08x, 0x%08x)",
                k.a[0], k.a[1], k.a[2], k.a[3], k.b[0], k.b[1], k.b[2], k.b[3], k.u[0], k.u[1], k.u[2], k.u[3]);
  return s;
}

const char* metric_name(Metric m) { return m == Metric::fields ? "fields" : m == Metric::ulp ? "ulp" : "abs"; }

// ================================ Tests ================================

TEST(GpuMathSpecs, EveryFunctionIdOnce) {
  ASSERT_EQ(int(std::size(kSpecs)), MSM_K_COUNT);
  for (int id = 0; id < MSM_K_COUNT; ++id) {
    EXPECT_EQ(std::count_if(std::begin(kSpecs), std::end(kSpecs), [&](const Spec& s) { return s.id == id; }), 1) << id;
    EXPECT_FALSE(outputs(spec_of(id)).empty()) << spec_of(id).name << " compares nothing";
  }
}

// The comparison rejects a result off by more than the tolerance in any one compared output, which
// is what a wrong device result looks like. (No device needed; GpuMath below uses the same code.)
TEST(GpuMathSpecs, ComparisonRejectsAPerturbedResult) {
  for (const Spec& spec : kSpecs) {
    std::vector<KernelIO> in = make_inputs(spec.id, 200);
    std::vector<KernelIO> cpu = run_on_cpu(spec.id, in);
    ASSERT_EQ(compare(spec, cpu, cpu).max, 0.0) << spec.name;
    for (int i : outputs(spec)) {
      std::vector<KernelIO> wrong = cpu;
      size_t n = 17;
      KernelIO& w = wrong[n];
      if (spec.metric == Metric::fields) {
        Field f = fields(spec.layout)[i];
        uint32_t field = (w.u[f.word] >> f.shift) & ((1u << f.bits) - 1u);
        uint32_t step = uint32_t(spec.max_tol) + 1u;
        w.u[f.word] += (field >= step ? 0u - step : step) << f.shift; // stays inside the field
      } else {
        float& v = channel(w, i);
        if (spec.shape == Shape::nodes && std::abs(v) >= kFar) continue; // all of infinity is one point
        if (spec.metric == Metric::ulp && std::abs(v) < std::numeric_limits<float>::min())
          v = std::numeric_limits<float>::min(); // subnormals compare as 0
        else if (spec.metric == Metric::ulp)
          for (int k = 0; k <= int(spec.max_tol); ++k) v = std::nextafter(v, std::numeric_limits<float>::infinity());
        else
          v = float(double(v) + (2.0 * spec.max_tol + 1e-6) * std::max(1.0, std::abs(double(v))));
      }
      Comparison r = compare(spec, wrong, cpu);
      EXPECT_FALSE(within(spec, r, in.size())) << spec.name << " output " << i << ": max " << r.max;
      EXPECT_EQ(r.worst, n) << spec.name << " output " << i;
    }
  }
}

// The device's results for function `id` from the kernels program of `ctx`.
std::vector<KernelIO> run_kernels(vk::Context& ctx, const vk::Program& program, int id,
                                  const std::vector<KernelIO>& in) {
  VkDeviceSize size = in.size() * sizeof(KernelIO);
  vk::Buffer src = vk::create_buffer(ctx, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
  vk::Buffer dst = vk::create_buffer(ctx, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
  // glm's vectors are standard-layout floats with a user-written copy constructor (so not
  // TriviallyCopyable to the standard); their bytes are exactly what the shader reads.
  static_assert(std::is_standard_layout_v<KernelIO> && sizeof(KernelIO) == 48);
  std::memcpy(src.data(), in.data(), size); // NOLINT(bugprone-undefined-memory-manipulation): see above
  std::memset(dst.data(), 0xFF, size);      // NaN everywhere: an output the shader did not write shows
  struct Push {
    int32_t function;
    uint32_t count;
  } push{id, uint32_t(in.size())};
  vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    vk::dispatch(cmd, program, vk::group_count(push.count, 64), 1, 1,
                 {{MSM_BINDING_KERNELS_INPUTS, src}, {MSM_BINDING_KERNELS_OUTPUTS, dst}}, push);
  });
  std::vector<KernelIO> out(in.size());
  std::memcpy(static_cast<void*>(out.data()), dst.data(), size); // KernelIO: glm's operator=, plain bytes
  return out;
}

vk::Program kernels_program(vk::Context& ctx) {
  return vk::create_program(ctx, "kernels",
                            {{MSM_BINDING_KERNELS_INPUTS, vk::Binding::storage_buffer},
                             {MSM_BINDING_KERNELS_OUTPUTS, vk::Binding::storage_buffer}},
                            2 * sizeof(uint32_t));
}

// A second Context on the same device whose pipelines use the native fma() whether it is fused or
// not (ContextOptions::FmaMode::Native): what msm_fma would compute without the emulation.
struct NativeFma {
  std::unique_ptr<vk::Context> ctx;
  std::unique_ptr<vk::Program> program;
  NativeFma() {
    vk::ContextOptions options = vk::test::test_options();
    options.verbose = false;
    options.fma_mode = vk::ContextOptions::FmaMode::native;
    ctx = std::make_unique<vk::Context>(options);
    program = std::make_unique<vk::Program>(kernels_program(*ctx));
  }
  ~NativeFma() { program.reset(); } // before its Context
  std::vector<KernelIO> run(int id, const std::vector<KernelIO>& in) { return run_kernels(*ctx, *program, id, in); }
};

// shared.h's msm_fma_emulated (what msm_fma is on devices whose fma() is not fused) is correctly
// rounded: bit for bit std::fma, on random operands over 2^±40 and on the hard cases: cancellation
// (c = -RN(a b)), c anywhere from far above to far below a b, exact ties (few-bit operands),
// near-ties (c below half an ulp of a b) and ties of a b broken by a tiny c. Its C++ build, like the GLSL one, rounds every operation
// once (-ffp-contract=off). No device needed; the device's build is checked by 'fma' below and by
// vk_test.cpp.
TEST(GpuMathSpecs, EmulatedFmaIsCorrectlyRounded) {
  std::mt19937_64 rng(20240611);
  std::uniform_int_distribution<uint32_t> mantissa(0, (1u << 23) - 1);
  std::uniform_int_distribution<int> exponent(-40, 40), shift(-30, 30), kind(0, 7);
  auto random_float = [&](int e) {
    float x = std::ldexp(1.0f + float(mantissa(rng)) * 0x1p-23f, e);
    return rng() & 1 ? -x : x;
  };
  long mismatches = 0, n = 0;
  auto check = [&](float a, float b, float c) {
    float got = msm_fma_emulated(a, b, c), want = std::fma(a, b, c);
    ++n;
    if (std::bit_cast<uint32_t>(got) != std::bit_cast<uint32_t>(want) && !(got == 0.0f && want == 0.0f) &&
        ++mismatches <= 5)
      ADD_FAILURE() << std::hexfloat << "msm_fma_emulated(" << a << ", " << b << ", " << c << ") = " << got
                    << ", std::fma: " << want;
  };
  for (int i = 0; i < 6000000; ++i) {
    float a = random_float(exponent(rng)), b = random_float(exponent(rng)), c = 0.0f;
    float p = a * b;
    switch (kind(rng)) {
    case 0: c = random_float(exponent(rng)); break;
    case 1: c = -p; break; // the residual of the product: b2 - b1 b1
    case 2: c = std::ldexp(random_float(0), std::ilogb(p) + shift(rng)); break;
    case 3: c = -p + std::ldexp(float(int(mantissa(rng) % 64) - 32), std::ilogb(p) - 23 + shift(rng) % 3); break;
    case 4: // few-bit operands: exact products, many exact ties
      a = float(int(mantissa(rng) % 4096) + 1) * std::ldexp(1.0f, exponent(rng) % 5);
      b = float(int(mantissa(rng) % 8192) + 1) * std::ldexp(1.0f, exponent(rng) % 5);
      c = float(int(mantissa(rng)) - (1 << 22)) * std::ldexp(1.0f, shift(rng) % 8);
      break;
    case 5: c = std::ldexp(random_float(0), std::ilogb(p) - 24 - int(mantissa(rng) % 40)); break; // near ties
    case 6: // a b exactly half-way between two floats, c far below it: only the rounding to odd of
            // t + e keeps c's side of the tie (without it: 2% of these come out wrong)
      a = float(4097 + 2 * int(mantissa(rng) % 4000)) * 0x1p-12f;
      b = float(4097 + 2 * int(mantissa(rng) % 4000)) * 0x1p-12f;
      c = std::ldexp(random_float(0), -20 - int(mantissa(rng) % 50));
      break;
    default:
      c = random_float(0) * 0.5f;
      a = random_float(0) * 0.5f;
      b = random_float(0) * 0.5f;
      break; // moments
    }
    check(a, b, c);
  }
  for (const KernelIO& x : make_inputs(MSM_K_FMA, kInputs)) check(x.a[0], x.a[1], x.a[2]);
  EXPECT_EQ(mismatches, 0) << "of " << n;
}

// One test per function id, on the device through msm_fma as this device's pipelines get it
// (Context::use_native_fma(): the native fma() where the Context's probe found it fused, else the exact
// emulation; MSM_FORCE_EMULATED_FMA=1 forces the emulation). Where fma() is not fused the device
// also runs the shader with the native fma() (NativeFma), printed as 'native fma': what msm_fma
// would give there without the emulation.
class GpuMath : public vk::test::VulkanTest, public ::testing::WithParamInterface<int> {
 protected:
  static void TearDownTestSuite() {
    program.reset();
    native.reset();
  }

  std::vector<KernelIO> run_on_device(int id, const std::vector<KernelIO>& in) {
    if (!program) program = std::make_unique<vk::Program>(kernels_program(ctx()));
    return run_kernels(ctx(), *program, id, in);
  }
  std::vector<KernelIO> run_native(int id, const std::vector<KernelIO>& in) {
    if (!native) native = std::make_unique<NativeFma>();
    std::size_t first = native->ctx->validation().count();
    std::vector<KernelIO> out = native->run(id, in);
    EXPECT_TRUE(vk::test::no_validation_messages(native->ctx->validation(), first)) << "native-fma context";
    return out;
  }

 private:
  static inline std::unique_ptr<vk::Program> program;
  static inline std::unique_ptr<NativeFma> native;
};

// The Context's probe (fma_probe.comp, a few constructed cases) against the device's native fma()
// on the 10^4 realistic inputs of test 'fma': a probe that says fused must be right on all of them.
// (A device whose fma() passes them but not the probe, e.g. one that evaluates in double and rounds
// twice, gets the emulation; that is printed, not a failure.)
TEST_F(GpuMath, DeviceFmaProbe) {
  std::vector<KernelIO> in = make_inputs(MSM_K_FMA, 10000);
  NativeFma native;
  Comparison r = compare(spec_of(MSM_K_FMA), native.run(MSM_K_FMA, in), run_on_cpu(MSM_K_FMA, in));
  bool fused_on_inputs = r.max == 0.0;
  std::printf("[gpu-math] device fma(): probe %s, realistic inputs %s (max %.3g ulp); msm_fma %s\n",
              ctx().fused_fma() ? "fused" : "NOT fused", fused_on_inputs ? "fused" : "NOT fused", r.max,
              ctx().use_native_fma() ? "native fma()" : "emulated");
  if (ctx().fused_fma()) { EXPECT_TRUE(fused_on_inputs) << "the probe missed a twice-rounded fma()"; }
  EXPECT_TRUE(vk::test::no_validation_messages(native.ctx->validation()));
}

TEST_P(GpuMath, AgreesWithCpu) {
  const Spec& spec = spec_of(GetParam());
  auto start = std::chrono::steady_clock::now();
  std::vector<KernelIO> in = make_inputs(spec.id, spec.inputs);
  std::vector<KernelIO> cpu = run_on_cpu(spec.id, in);
  std::unique_ptr<std::vector<KernelIO>> cpu_ties_down = run_on_cpu_ties_down(spec, in);
  std::vector<KernelIO> gpu = run_on_device(spec.id, in);
  Comparison r = compare(spec, gpu, cpu, cpu_ties_down.get());
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::printf("[gpu-math] %-29s %-6s n=%zu max %-9.3g p99.9 %-9.3g differ %6.2f%%", spec.name, metric_name(spec.metric),
              in.size(), r.max, r.p999, 100.0 * differing(r, in.size()));
  if (r.ties) std::printf(" (ties %zu)", r.ties);
  std::printf(" | tol max %g p99.9 %g", spec.max_tol, spec.p999_tol);
  if (spec.differ_tol < 1.0) std::printf(" differ %g%%", 100.0 * spec.differ_tol);
  std::printf(" | msm_fma %s", ctx().use_native_fma() ? "native" : "emulated");
  if (!ctx().fused_fma()) {
    Comparison n = compare(spec, run_native(spec.id, in), cpu, cpu_ties_down.get());
    std::printf(" | native fma: max %.3g p99.9 %.3g", n.max, n.p999);
  }
  std::printf(" | %.2fs\n", seconds);

  if (finite_outputs(spec.id)) {
    size_t non_finite = 0;
    for (size_t n = 0; n < in.size(); ++n)
      for (int i : outputs(spec))
        non_finite += !std::isfinite(channel(gpu[n], i)) || !std::isfinite(channel(cpu[n], i));
    EXPECT_EQ(non_finite, 0u) << spec.name << ": outputs that are not finite (device or CPU)";
  }
  EXPECT_TRUE(within(spec, r, in.size()))
      << spec.name << ": max " << r.max << " (tol " << spec.max_tol << "), p99.9 " << r.p999 << " (tol "
      << spec.p999_tol << "), differing " << differing(r, in.size()) << " (tol " << spec.differ_tol << ")"
      << " [msm_fma " << (ctx().use_native_fma() ? "native" : "emulated") << "]\n worst input " << describe(in[r.worst])
      << "\n   device " << describe(gpu[r.worst]) << "\n   cpu    " << describe(cpu[r.worst]);
}

INSTANTIATE_TEST_SUITE_P(Functions, GpuMath, ::testing::Range(0, MSM_K_COUNT),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return std::string(spec_of(info.param).name);
                         });

} // namespace
