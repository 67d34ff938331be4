#include "msm/viewer/script.h"

#include "msm/render/renderer.h"
#include "msm/techniques.h"
#include "msm/util/spelling.h"
#include "msm/viewer/lights.h"
#include "msm/viewer/view_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace msm::viewer {
namespace {

struct Verb {
  std::string_view name;
  int min_args, max_args; // -1: rest of the line
};

constexpr Verb kVerbs[] = {{"technique", 1, 1},      {"set", 2, -1},         {"camera", 6, 6},
                           {"light", 3, 3},          {"split", 1, 1},        {"divider", 1, 1},
                           {"load-view", 1, 1},      {"save-view", 1, 1},    {"screenshot", 1, 1},
                           {"panel-mask", 1, 1},     {"resize", 2, 2},       {"frames", 1, 1},
                           {"object-frame", 1, 1},   {"close", 0, 0},        {"quit", 0, 0},
                           {"each-technique", 0, 0}, {"ground-truth", 1, 1}, {"wait-ground-truth", 0, 0},
                           {"show-truth", 1, 1},     {"scene", 1, 1},        {"reload", 0, 0},
                           {"show-map", 1, 1},       {"panel", 1, 1},        {"light-add", 1, 1},
                           {"light-remove", 1, 1},   {"light-on", 1, 1},     {"light-off", 1, 1},
                           {"light-move", 4, 4},     {"light-set", 3, -1}};

double parse_number(const std::string& where, const std::string& text) {
  double v = 0;
  auto [end, err] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (err != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    throw ScriptError(fmt::format("{}: '{}' is not a number", where, text));
  return v;
}

// A light's number in the view's list (the panel's numbers), 0..kMaxLights - 1.
void check_light_number(const Action& a) {
  double v = parse_number(a.where, a.args[0]);
  if (v != std::floor(v) || v < 0 || v >= scene::kMaxLights)
    throw ScriptError(fmt::format("{}: {} {}: a light's number, an integer in [0, {}]", a.where, a.verb, a.args[0],
                                  scene::kMaxLights - 1));
}

// light-add KIND, light-remove|on|off N, light-move N X Y Z, light-set N KEY VALUE.
void check_light_action(const Action& a) {
  const std::string& w = a.where;
  if (a.verb == "light-add") {
    if (scene::parse_light_kind(a.args[0])) return;
    std::vector<std::string> names;
    for (const scene::LightKindInfo& k : scene::light_kinds()) names.emplace_back(k.name);
    throw ScriptError(
        fmt::format("{}: light-add {}: unknown kind of light{}", w, a.args[0], util::did_you_mean(a.args[0], names)));
  }
  check_light_number(a);
  if (a.verb == "light-move") {
    for (size_t i = 1; i < a.args.size(); ++i) parse_number(w, a.args[i]);
  } else if (a.verb == "light-set") {
    const std::vector<std::string> keys = light_keys();
    if (std::find(keys.begin(), keys.end(), a.args[1]) == keys.end())
      throw ScriptError(fmt::format("{}: light-set {}: no kind of light has this key{}", w, a.args[1],
                                    util::did_you_mean(a.args[1], keys)));
  }
}

// The checks that need no window: names, keys, values and ranges.
void check(const Action& a) {
  const std::string& w = a.where;
  if (a.verb == "technique" || (a.verb == "split" && a.args[0] != "off")) {
    try {
      render::find_rendered_technique(canonical_technique_name(a.args[0]));
    } catch (const render::RenderError& e) { throw ScriptError(fmt::format("{}: {}", w, e.what())); }
  } else if (a.verb == "set") {
    render::RenderSettings scratch;
    try {
      apply_setting(scratch, a.args[0], setting_value(a.args[1]));
    } catch (const ViewError& e) { throw ScriptError(fmt::format("{}: set {}", w, e.what())); }
  } else if (a.verb == "camera" || a.verb == "light") {
    for (const std::string& arg : a.args) parse_number(w, arg);
  } else if (a.verb == "divider") {
    double f = parse_number(w, a.args[0]);
    if (!(f > 0 && f < 1)) throw ScriptError(fmt::format("{}: divider {} is outside (0, 1)", w, a.args[0]));
  } else if (a.verb == "resize") {
    for (const std::string& arg : a.args) {
      double v = parse_number(w, arg);
      if (v != std::floor(v) || v < 64 || v > 8192)
        throw ScriptError(fmt::format("{}: resize {} {}: sizes are integers in [64, 8192]", w, a.args[0], a.args[1]));
    }
  } else if (a.verb == "ground-truth") {
    double v = parse_number(w, a.args[0]);
    if (v != std::floor(v) || v < 1 || v > 65536)
      throw ScriptError(fmt::format("{}: ground-truth {}: samples are an integer in [1, 65536]", w, a.args[0]));
  } else if (a.verb == "panel") {
    if (a.args[0] != "open" && a.args[0] != "collapsed")
      throw ScriptError(fmt::format("{}: panel {}: open or collapsed", w, a.args[0]));
  } else if (a.verb == "show-truth" || a.verb == "show-map") {
    if (a.args[0] != "on" && a.args[0] != "off")
      throw ScriptError(fmt::format("{}: {} {}: on or off", w, a.verb, a.args[0]));
  } else if (a.verb.starts_with("light-")) {
    check_light_action(a);
  } else if (a.verb == "frames") {
    double v = parse_number(w, a.args[0]);
    if (v != std::floor(v) || v < 0 || v > 100000)
      throw ScriptError(fmt::format("{}: frames {}: expected an integer in [0, 100000]", w, a.args[0]));
  } else if (a.verb == "object-frame") {
    double v = parse_number(w, a.args[0]);
    if (v != std::floor(v) || v < 0 || v > kMaxObjectFrame)
      throw ScriptError(
          fmt::format("{}: object-frame {}: expected an integer in [0, {}]", w, a.args[0], kMaxObjectFrame));
  }
}

} // namespace

nlohmann::json setting_value(const std::string& text) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error&) { return text; } // a bare word
}

std::vector<Action> parse_script(std::string_view text, const std::string& name) {
  std::vector<Action> out;
  std::istringstream in{std::string(text)};
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    Action a;
    a.line = number;
    a.where = fmt::format("{}:{}", name, number);
    if (!(words >> a.verb)) continue;
    const Verb* verb = nullptr;
    for (const Verb& v : kVerbs)
      if (v.name == a.verb) verb = &v;
    if (!verb) {
      std::vector<std::string> names;
      for (const Verb& v : kVerbs) names.emplace_back(v.name);
      throw ScriptError(fmt::format("{}: unknown action '{}'{}", a.where, a.verb, util::did_you_mean(a.verb, names)));
    }
    std::string word;
    if (verb->max_args < 0) { // the first min_args - 1 words, then the rest of the line as one
      for (int k = 0; k + 1 < verb->min_args && words >> word; ++k) a.args.push_back(word);
      std::string rest;
      std::getline(words, rest);
      size_t first = rest.find_first_not_of(" \t\r");
      if (first != std::string::npos) a.args.push_back(rest.substr(first, rest.find_last_not_of(" \t\r") - first + 1));
    } else {
      while (words >> word) a.args.push_back(word);
    }
    if (int(a.args.size()) < verb->min_args || (verb->max_args >= 0 && int(a.args.size()) > verb->max_args))
      throw ScriptError(fmt::format("{}: {} takes {} argument{}, got {}", a.where, a.verb, verb->min_args,
                                    verb->min_args == 1 ? "" : "s", a.args.size()));
    check(a);
    out.push_back(std::move(a));
  }
  return out;
}

std::vector<Action> load_script(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ScriptError(fmt::format("{}: cannot open the script", file.string()));
  std::stringstream text;
  text << in.rdbuf();
  return parse_script(text.str(), file.string());
}

} // namespace msm::viewer
