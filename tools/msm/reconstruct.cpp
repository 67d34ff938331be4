// `msm techniques` and `msm reconstruct`: the CPU pipeline of every technique on a kernel given
// on the command line.
#include "commands.h"
#include "msm/cpu/techniques.h"
#if MSM_TOOL_RENDER
#include "msm/render/renderer.h"
#endif

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace msm::tool {

void add_techniques(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "techniques",
      "List the shadow techniques: storage per texel, where they run (renderer, CPU pipeline), parameters");
  cmd->callback([] {
    fmt::print("{:<26} {:>4}  {:<12} {}\n", "technique", "bits", "runs in", "description");
#if MSM_TOOL_RENDER
    for (const render::Technique& t : render::techniques()) {
      bool cpu = false;
      for (const cpu::Technique& c : cpu::techniques()) cpu = cpu || c.name == t.name;
      fmt::print("{:<26} {:>4}  {:<12} {}\n", t.name, t.bits_per_texel, cpu ? "render, cpu" : "render", t.description);
      if (!t.parameters.empty()) {
        glm::vec4 p = render::default_params(t);
        fmt::print("{:<26} {:>4}  {:<12} --param {},{},{},{} ({})\n", "", "", "", p.x, p.y, p.z, p.w, t.parameters);
      }
    }
    for (const cpu::Technique& t : cpu::techniques()) {
      bool rendered = false;
      for (const render::Technique& r : render::techniques()) rendered = rendered || r.name == t.name;
      if (!rendered) fmt::print("{:<26} {:>4}  {:<12} {}\n", t.name, t.bits_per_texel, "cpu", t.description);
    }
#else
    for (const cpu::Technique& t : cpu::techniques())
      fmt::print("{:<26} {:>4}  {:<12} {}\n", t.name, t.bits_per_texel, "cpu", t.description);
#endif
  });
}

void add_reconstruct(CLI::App& app) {
  struct Options {
    std::vector<float> depths, weights;
    float zf = 0.5f;
    std::vector<std::string> techniques;
    bool json = false;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "reconstruct", "Shadow intensity every technique reconstructs for a filter kernel holding the given depths");
  cmd->add_option("--depths", opt->depths, "Occluder depths in the kernel, in [0,1]")->required()->delimiter(',');
  cmd->add_option("--weights", opt->weights, "Filter weights (default: equal)")->delimiter(',');
  cmd->add_option("--zf", opt->zf, "Fragment depth in [0,1]")->required();
  cmd->add_option("--technique", opt->techniques, "Techniques to run (default: all)")->delimiter(',');
  cmd->add_flag("--json", opt->json, "Print JSON");
  cmd->callback([opt] {
    auto finite_unit = [](float x) { return std::isfinite(x) && x >= 0.0f && x <= 1.0f; };
    for (float d : opt->depths)
      if (!finite_unit(d)) throw UsageError(fmt::format("depth {} is not in [0,1]", d));
    if (!finite_unit(opt->zf)) throw UsageError(fmt::format("--zf {} is not in [0,1]", opt->zf));
    if (opt->weights.empty()) opt->weights.assign(opt->depths.size(), 1.0f);
    if (opt->weights.size() != opt->depths.size())
      throw UsageError(fmt::format("{} weights for {} depths", opt->weights.size(), opt->depths.size()));
    for (float w : opt->weights)
      if (!(std::isfinite(w) && w >= 0.0f)) throw UsageError(fmt::format("weight {} is not >= 0", w));

    std::vector<const cpu::Technique*> chosen;
    if (opt->techniques.empty())
      for (const cpu::Technique& t : cpu::techniques()) chosen.push_back(&t);
    for (const std::string& name : opt->techniques) chosen.push_back(&cpu::find_technique(name));

    float reference = cpu::percentage_closer(opt->depths, opt->weights, opt->zf);
    nlohmann::ordered_json out;
    out["zf"] = opt->zf;
    out["pcf"] = std::round(reference * 1e6) / 1e6;
    for (const cpu::Technique* t : chosen)
      out["techniques"][std::string(t->name)] = cpu::filtered_shadow(*t, opt->depths, opt->weights, opt->zf);
    if (opt->json) {
      fmt::print("{}\n", out.dump(2));
      return;
    }
    fmt::print("{:<26} {:.4f}\n", "pcf (exact)", reference);
    for (const cpu::Technique* t : chosen)
      fmt::print("{:<26} {:.4f}\n", t->name, out["techniques"][std::string(t->name)].get<float>());
  });
}

} // namespace msm::tool
