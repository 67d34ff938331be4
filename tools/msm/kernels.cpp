// `msm kernels`: every technique of the CPU pipeline on the filter-kernel situations the papers
// use to show their artifacts, against the exact answer (percentage-closer filtering of the same
// kernel). Needs no device.
#include "commands.h"
#include "msm/cpu/techniques.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace msm::tool {
namespace {

struct Example {
  std::string name;
  std::vector<float> depths, weights;
  float zf; // just in front of the receiver, as a small depth bias would put it
};

// A sloped receiver: 64 depths evenly spread over [lo, hi].
Example slope(std::string name, float lo, float hi, float zf) {
  Example e{std::move(name), {}, {}, zf};
  for (int i = 0; i < 64; ++i) {
    e.depths.push_back(lo + (hi - lo) * (i + 0.5f) / 64.0f);
    e.weights.push_back(1.0f);
  }
  return e;
}

std::vector<Example> paper_examples() {
  return {
      {"penumbra: occluder edge over ground (2 depths)", {0.30f, 0.60f}, {0.4f, 0.6f}, 0.598f},
      {"short range: banner under railing (HPG Fig. 1)", {0.55f, 0.57f}, {0.5f, 0.5f}, 0.568f},
      {"contact shadow: occluder touching receiver", {0.595f, 0.60f}, {0.5f, 0.5f}, 0.599f},
      {"three occluders in one kernel (JCGT Fig. 4)", {0.20f, 0.35f, 0.50f}, {0.3f, 0.3f, 0.4f}, 0.80f},
      {"two occluders + lit ground (JCGT Fig. 4 cyan)", {0.25f, 0.45f, 0.70f}, {0.35f, 0.35f, 0.3f}, 0.698f},
      {"Dirac pair at far plane (HPG §3.2)", {0.9575f, 1.0f}, {0.5f, 0.5f}, 0.99f},
      slope("sloped receiver, no occluder (acne test)", 0.50f, 0.52f, 0.52f - 0.005f),
  };
}

} // namespace

void add_kernels(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "kernels", "Print every technique's reconstruction on the papers' example kernels against the exact answer");
  cmd->callback([] {
    std::vector<Example> examples = paper_examples();
    fmt::print("Shadow intensity (0 = lit, 1 = shadowed) per filter kernel; exact = PCF of the same kernel.\n");
    fmt::print("Light leaking shows as values below exact, wrong self-shadowing as values above.\n\n");
    for (size_t i = 0; i < examples.size(); ++i)
      fmt::print("  K{}: {} (zf = {})\n", i + 1, examples[i].name, examples[i].zf);
    fmt::print("\n{:<26} {:>5}", "technique", "bits");
    for (size_t i = 0; i < examples.size(); ++i) fmt::print(" {:>6}", fmt::format("K{}", i + 1));
    fmt::print(" {:>8}\n", "max|err|");
    fmt::print("{:<26} {:>5}", "exact (PCF)", "");
    for (const Example& e : examples) fmt::print(" {:>6.3f}", cpu::percentage_closer(e.depths, e.weights, e.zf));
    fmt::print("\n");
    for (const Technique& t : techniques()) {
      if (!t.on_cpu()) continue;
      fmt::print("{:<26} {:>5}", t.name, t.bits_per_texel);
      float worst = 0.0f;
      for (const Example& e : examples) {
        float s = cpu::filtered_shadow(t, e.depths, e.weights, e.zf);
        worst = std::max(worst, std::abs(s - cpu::percentage_closer(e.depths, e.weights, e.zf)));
        fmt::print(" {:>6.3f}", s);
      }
      fmt::print(" {:>8.3f}\n", worst);
    }
  });
}

} // namespace msm::tool
