// `msm techniques` and `msm reconstruct`: the CPU pipeline of every technique on a kernel given
// on the command line.
#include "commands.h"
#include "msm/cpu/techniques.h"
#if MSM_TOOL_RENDER
#include "msm/render/renderer.h"
#endif

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace msm::tool {

void add_techniques(CLI::App& app) {
  auto passes = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand(
      "techniques", "List the shadow techniques of the technique table (msm/cpu/techniques.h): storage per texel, "
                    "where they run (renderer, CPU pipeline), parameters, and with --passes the passes of each "
                    "one's frame");
  cmd->add_flag("--passes", *passes,
                "Print the passes of each rendered technique's frame in execution order (default settings; "
                "translucent and coloured variants where the technique blends translucent occluders)");
  cmd->callback([passes] {
    fmt::print("{:<26} {:>4}  {:<12} {}\n", "technique", "bits", "runs in", "description");
    for (const Technique& t : techniques()) {
      std::string where = t.rendered && t.on_cpu() ? "render, cpu" : t.rendered ? "render" : "cpu";
      fmt::print("{:<26} {:>4}  {:<12} {}\n", t.name, t.bits_per_texel, where, t.description);
      if (std::string aliases = technique_alias_list(t.name); !aliases.empty())
        fmt::print("{:<26} {:>4}  {:<12} alias: {}\n", "", "", "", aliases);
      if (!t.parameters.empty()) {
        glm::vec4 p = t.default_params();
        fmt::print("{:<26} {:>4}  {:<12} --param {},{},{},{} ({})\n", "", "", "", p.x, p.y, p.z, p.w, t.parameters);
      }
#if MSM_TOOL_RENDER
      if (*passes && t.rendered) {
        fmt::print("{:<26} {:>4}  {:<12} passes: {}\n", "", "", "", fmt::join(render::technique_passes(t), " > "));
        if (render::supports_translucency(t)) {
          fmt::print("{:<26} {:>4}  {:<12} translucent: {}\n", "", "", "",
                     fmt::join(render::technique_passes(t, true), " > "));
          fmt::print("{:<26} {:>4}  {:<12} coloured: {}\n", "", "", "",
                     fmt::join(render::technique_passes(t, true, true), " > "));
        }
      }
#endif
    }
#if !MSM_TOOL_RENDER
    if (*passes) throw UsageError("--passes: this msm was built without the renderer (MSM_BUILD_VULKAN=OFF)");
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
  cmd->add_option("--technique,-t", opt->techniques, "Techniques or aliases to run (default: all)")->delimiter(',');
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

    std::vector<const Technique*> chosen;
    if (opt->techniques.empty())
      for (const Technique& t : techniques())
        if (t.on_cpu()) chosen.push_back(&t);
    for (const std::string& name : opt->techniques) {
      const Technique& t = find_technique(name);
      if (!t.on_cpu())
        throw UsageError(
            fmt::format("{} runs in the renderer only (msm render); msm techniques lists where each runs", name));
      chosen.push_back(&t);
    }

    float reference = cpu::percentage_closer(opt->depths, opt->weights, opt->zf);
    nlohmann::ordered_json out;
    out["zf"] = opt->zf;
    out["pcf"] = std::round(reference * 1e6) / 1e6;
    for (const Technique* t : chosen)
      out["techniques"][std::string(t->name)] = cpu::filtered_shadow(*t, opt->depths, opt->weights, opt->zf);
    if (opt->json) {
      fmt::print("{}\n", out.dump(2));
      return;
    }
    fmt::print("{:<26} {:.4f}\n", "pcf (exact)", reference);
    for (const Technique* t : chosen)
      fmt::print("{:<26} {:.4f}\n", t->name, out["techniques"][std::string(t->name)].get<float>());
  });
}

} // namespace msm::tool
