// `msm techniques` and `msm reconstruct`: the CPU pipeline of every technique on a kernel given
// on the command line.
#include "commands.h"
#include "msm/cpu/techniques.h"
#include "usage.h"
#include "vocabulary.h"
#if MSM_TOOL_RENDER
#include "msm/render/renderer.h"
#endif

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace msm::tool {

namespace {

std::string_view type_name(ParameterType type) {
  switch (type) {
  case ParameterType::number: return "number";
  case ParameterType::integer: return "integer";
  case ParameterType::flag: return "flag";
  case ParameterType::choice: return "choice";
  }
  return "number";
}

nlohmann::ordered_json parameter_json(const Parameter& p) {
  nlohmann::ordered_json j{{"name", p.name},
                           {"type", type_name(p.type)},
                           {"range", p.range_text()},
                           {"default", p.value_text(p.default_value)},
                           {"meaning", p.meaning}};
  for (const ParameterChoice& c : p.choices) j["choices"][std::string(c.name)] = c.meaning;
  return j;
}

nlohmann::ordered_json technique_json(const Technique& t) {
  nlohmann::ordered_json j{{"name", t.name},
                           {"aliases", technique_alias_list(t.name)},
                           {"description", t.description},
                           {"bits_per_texel", t.bits_per_texel},
                           {"renderer", t.rendered()},
                           {"cpu", t.on_cpu()},
                           {"parameters", nlohmann::ordered_json::array()}};
  for (const Parameter* p : t.parameter_list()) j["parameters"].push_back(parameter_json(*p));
  return j;
}

// One technique: its row, then a parameter per line with its type, range, default and meaning
// (and a choice's meaning per line).
void print_technique(const Technique& t) {
  std::string where = t.rendered() && t.on_cpu() ? "render, cpu" : t.rendered() ? "render" : "cpu";
  fmt::print("{} ({} bits per texel; runs in {})\n{}\n", t.name, t.bits_per_texel, where, t.description);
  if (std::string aliases = technique_alias_list(t.name); !aliases.empty()) fmt::print("alias: {}\n", aliases);
  if (t.parameter_list().empty()) {
    fmt::print("no parameters\n");
    return;
  }
  fmt::print("parameters (--set NAME=VALUE):\n");
  for (const Parameter* p : t.parameter_list()) {
    fmt::print("  {:<18} {:<8} {:<36} default {}\n", p->name, type_name(p->type), p->range_text(),
               p->value_text(p->default_value));
    fmt::print("  {:<18} {}\n", "", p->meaning);
    for (const ParameterChoice& c : p->choices) fmt::print("  {:<18}   {}: {}\n", "", c.name, c.meaning);
  }
}

} // namespace

void add_techniques(CLI::App& app) {
  struct Options {
    bool passes = false, json = false;
    std::string name;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "techniques", "List the shadow techniques of the technique table (msm/cpu/techniques.h): storage per texel, "
                    "where they run (renderer, CPU pipeline), parameters, and with --passes the passes of each "
                    "one's frame; with a NAME, that technique's parameters (name, type, range, default, meaning)");
  cmd->add_option("name", opt->name, "A technique or alias: its parameters");
  cmd->add_flag("--passes", opt->passes,
                "Print the passes of each rendered technique's frame in execution order (default settings; "
                "translucent and coloured variants where the technique blends translucent occluders)");
  add_term_flag(cmd, "--json", opt->json, ": every technique (or the one named) with its parameters");
  cmd->callback([opt] {
#if !MSM_TOOL_RENDER
    if (opt->passes) throw UsageError("--passes: this msm was built without the renderer (MSM_BUILD_VULKAN=OFF)");
#endif
    if (!opt->name.empty()) {
      const Technique* t = nullptr;
      try {
        t = &find_technique(opt->name);
      } catch (const std::invalid_argument& e) { throw UsageError(e.what()); }
      if (opt->json)
        fmt::print("{}\n", technique_json(*t).dump(2));
      else
        print_technique(*t);
      return;
    }
    if (opt->json) {
      nlohmann::ordered_json all = nlohmann::ordered_json::array();
      for (const Technique& t : techniques()) all.push_back(technique_json(t));
      fmt::print("{}\n", all.dump(2));
      return;
    }
    fmt::print("{:<26} {:>4}  {:<12} {}\n", "technique", "bits", "runs in", "description");
    for (const Technique& t : techniques()) {
      std::string where = t.rendered() && t.on_cpu() ? "render, cpu" : t.rendered() ? "render" : "cpu";
      fmt::print("{:<26} {:>4}  {:<12} {}\n", t.name, t.bits_per_texel, where, t.description);
      if (std::string aliases = technique_alias_list(t.name); !aliases.empty())
        fmt::print("{:<26} {:>4}  {:<12} alias: {}\n", "", "", "", aliases);
      if (!t.parameter_list().empty()) {
        std::string names;
        for (const Parameter* p : t.parameter_list())
          names += (names.empty() ? "" : ", ") + std::string(p->name) + "=" + p->value_text(p->default_value);
        fmt::print("{:<26} {:>4}  {:<12} parameters: {} (msm techniques {})\n", "", "", "", names, t.name);
      }
#if MSM_TOOL_RENDER
      if (opt->passes && t.rendered()) {
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
  add_term(cmd, "--techniques", opt->techniques, ", to run (default: all)")->delimiter(',');
  add_deprecated_option(cmd, "--technique", "-t/--techniques", opt->techniques)->delimiter(',');
  add_term_flag(cmd, "--json", opt->json);
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
