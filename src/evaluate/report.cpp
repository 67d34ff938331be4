// Tables, histogram and summary of an evaluation (report.h).
#include "msm/evaluate/report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <span>

#include <fmt/format.h>

#include "msm/evaluate/functions.h"
#include "msm/image/compose.h"
#include "msm/image/io.h"

namespace msm::evaluate {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

void write_text(const fs::path& file, const std::string& text) {
  image::write_file_atomic(file, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

std::string csv_quoted(std::string_view s) {
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string join(const std::vector<std::string>& parts, std::string_view separator) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : std::string(separator)) + p;
  return out;
}

std::string formulas(const Candidate& c) {
  std::vector<std::string> parts;
  for (int f : c.functions) parts.emplace_back(candidate_functions()[f].formula);
  return join(parts, "; ");
}

// Shortest text that reads back as the same double ("nan" for NaN).
std::string number(double x) { return std::isnan(x) ? std::string("nan") : fmt::format("{}", x); }

// The candidate with this alias or technique name, if the run has it.
const CandidateResult* find_named(const RunResult& run, std::string_view name) {
  for (std::size_t i = 0; i < run.candidates.size(); ++i)
    if (run.candidates[i].name == name || run.candidates[i].has_alias(name)) return &run.results[i];
  return nullptr;
}

// Candidates by error (ties by index), singular ones last.
std::vector<std::size_t> ranking_order(const RunResult& run) {
  std::vector<std::size_t> order(run.results.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double ea = run.results[a].error(), eb = run.results[b].error();
    if (std::isnan(ea) != std::isnan(eb)) return std::isnan(eb);
    return !std::isnan(ea) && ea < eb;
  });
  return order;
}

// The population that ranks and the histogram count: the LP candidates with the most common number
// of functions (4 where that ties: the paper's histogram is of its four-function sets), singular
// ones left out.
int reference_m(const RunResult& run) {
  std::map<int, int> count;
  for (std::size_t i = 0; i < run.results.size(); ++i)
    if (run.candidates[i].technique == Technique::lp && !run.results[i].singular) ++count[run.candidates[i].m()];
  int best = 4;
  for (const auto& [m, n] : count)
    if (n > (count.contains(best) ? count[best] : 0)) best = m;
  return best;
}

std::vector<double> lp_errors(const RunResult& run) {
  const int m = reference_m(run);
  std::vector<double> errors;
  for (std::size_t i = 0; i < run.results.size(); ++i)
    if (run.candidates[i].technique == Technique::lp && run.candidates[i].m() == m && !run.results[i].singular)
      errors.push_back(run.results[i].error());
  std::sort(errors.begin(), errors.end());
  return errors;
}

// ---- Drawing ----------------------------------------------------------------------------------

void fill(image::Image& img, int x0, int y0, int x1, int y1, glm::vec3 colour) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, img.width()), y1 = std::min(y1, img.height());
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = colour[c];
}

std::string percent(double error) { return fmt::format("{:.2f}%", 100.0 * error); }

// Text without a box. Through draw_label, whose style travels by reference: msm_image is compiled
// without GLM_FORCE_CTOR_INIT and this library with it, which makes glm::vec3 trivially copyable
// there and not here, so a glm::vec3 passed by value (draw_text's colour) would cross a calling
// convention mismatch.
void text(image::Image& img, int x, int y, std::string_view s, glm::vec3 colour, int scale) {
  image::LabelStyle style;
  style.text_colour = colour;
  style.box_opacity = 0.0f;
  style.scale = scale;
  image::draw_label(img, x - scale, y - scale, s, style);
}

} // namespace

void write_histogram(const fs::path& file, const std::vector<double>& errors, const std::vector<HistogramMark>& marks,
                     const std::string& title) {
  const int width = 1000, height = 560, left = 80, right = 30, top = 70, bottom = 70;
  const int plot_w = width - left - right, plot_h = height - top - bottom;
  image::Image img(width, height, 3, 1.0f);
  // The range of the candidates and the marks, except marks at 0 (PCF), which sit at the left edge
  // with an arrow when the range does not reach down to them.
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (double e : errors) lo = std::min(lo, e), hi = std::max(hi, e);
  for (const HistogramMark& m : marks)
    if (m.error > 0.0) lo = std::min(lo, m.error), hi = std::max(hi, m.error);
  if (!(hi > 0.0)) lo = 0.0, hi = 0.01;
  const double margin = 0.04 * (hi - lo) + 1e-6;
  lo = std::max(0.0, lo - margin);
  hi += margin;
  const auto to_x = [&](double e) { return left + int(std::lround((e - lo) / (hi - lo) * plot_w)); };
  const int bins = 80;
  std::vector<int> counts(bins, 0);
  for (double e : errors) counts[std::clamp(int((e - lo) / (hi - lo) * bins), 0, bins - 1)]++;
  const int most = std::max(1, *std::max_element(counts.begin(), counts.end()));
  const glm::vec3 ink(0.0f), bar(0.18f, 0.36f, 0.62f), grid_colour(0.85f), mark_colour(0.75f, 0.08f, 0.05f);

  text(img, left, 16, title, ink, 2);
  // Axes with ticks: x in percent, y in candidates.
  for (int k = 0; k <= 5; ++k) {
    const int y = top + plot_h - int(std::lround(double(k) / 5.0 * plot_h));
    fill(img, left, y, left + plot_w, y + 1, grid_colour);
    const std::string label = fmt::format("{}", int(std::lround(double(k) / 5.0 * most)));
    text(img, left - 10 - image::text_width(label, 1) * 2, y - 8, label, ink, 2);
  }
  for (int k = 0; k <= 8; ++k) {
    const int x = left + int(std::lround(double(k) / 8.0 * plot_w));
    fill(img, x, top + plot_h, x + 1, top + plot_h + 6, ink);
    const std::string label = percent(lo + (hi - lo) * k / 8.0);
    text(img, x - image::text_width(label, 2) / 2, top + plot_h + 12, label, ink, 2);
  }
  const std::string x_label = "mean error against PCF (L1 irradiance error / total radiant power)";
  text(img, left + plot_w / 2 - image::text_width(x_label, 2) / 2, height - 26, x_label, ink, 2);
  for (int b = 0; b < bins; ++b) {
    if (counts[b] == 0) continue;
    const int x0 = left + b * plot_w / bins, x1 = left + (b + 1) * plot_w / bins - 1;
    const int h = std::max(1, int(std::lround(double(counts[b]) / most * plot_h)));
    fill(img, x0, top + plot_h - h, x1, top + plot_h, bar);
  }
  fill(img, left, top, left + 1, top + plot_h + 1, ink);
  fill(img, left, top + plot_h, left + plot_w, top + plot_h + 1, ink);
  // Marks: a vertical line each, labels staggered in rows so that neighbours do not overlap.
  std::vector<HistogramMark> sorted = marks;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.error < b.error; });
  std::vector<int> row_end(6, -1000);
  for (const HistogramMark& m : sorted) {
    const bool off_scale = m.error < lo;
    const int x = off_scale ? left : to_x(m.error);
    fill(img, x - 1, top, x + 1, top + plot_h, mark_colour);
    const std::string label = fmt::format("{}{} {}", off_scale ? "<- " : "", m.label, percent(m.error));
    const int w = image::text_width(label, 2);
    int row = 0;
    while (row + 1 < int(row_end.size()) && row_end[row] > x + 4) ++row;
    image::LabelStyle style;
    style.text_colour = glm::vec3(1.0f);
    style.box_colour = mark_colour;
    style.box_opacity = 0.9f;
    image::draw_label(img, std::min(x + 4, width - w - 8), top + 6 + row * 26, label, style);
    row_end[row] = x + 4 + w + 12;
  }
  image::write_png(file, img);
}

json summary(const RunResult& run, const RunSettings& settings) {
  json j;
  j["settings"] = {{"scenes", settings.scenes},
                   {"shadow_map_size", settings.stack.size},
                   {"depth_grid_points", settings.stack.grid},
                   {"filter_taps", settings.stack.filter_taps},
                   {"filter_sigma", settings.stack.filter_sigma},
                   {"max_layers", settings.stack.max_layers},
                   {"max_bias", settings.stack.max_bias},
                   {"candidates", settings.candidates},
                   {"solve_lit", settings.evaluate.solve_lit}};
  json stacks = json::array();
  for (std::size_t s = 0; s < run.stacks.size(); ++s) {
    const StackStats& st = run.stacks[s];
    stacks.push_back({{"scene", run.scene_names[s]},
                      {"texels", st.texels},
                      {"covered_texels", st.covered_texels},
                      {"fragments", st.fragments},
                      {"counted_fragments", st.counted},
                      {"lit_fragments", st.lit},
                      {"max_layers", st.max_layers},
                      {"truncated_texels", st.truncated_texels},
                      {"bias_capped", st.bias_capped},
                      {"fingerprint", fmt::format("{:016x}", run.stack_fingerprints[s])}});
  }
  j["stacks"] = stacks;

  const std::vector<double> errors = lp_errors(run);
  const auto lp_rank = [&](double error) {
    return std::int64_t(std::lower_bound(errors.begin(), errors.end(), error) - errors.begin()) + 1;
  };
  const auto entry = [&](std::size_t i) {
    const Candidate& c = run.candidates[i];
    const CandidateResult& r = run.results[i];
    json e{{"index", i},
           {"name", c.name},
           {"technique", std::string(to_string(c.technique))},
           {"m", c.m()},
           {"aliases", c.aliases},
           {"error", r.singular ? json(nullptr) : json(r.error())},
           {"singular", r.singular}};
    if (!r.singular) {
      json per_scene = json::object();
      for (std::size_t s = 0; s < r.scenes.size(); ++s) per_scene[run.scene_names[s]] = r.scenes[s].error();
      e["scene_errors"] = per_scene;
      e["lp_rank"] = lp_rank(r.error());
      e["lp_percentile"] = errors.empty() ? 0.0 : 100.0 * double(lp_rank(r.error()) - 1) / double(errors.size());
      e["lp_failures"] = r.failures();
    }
    return e;
  };
  json named = json::array();
  for (std::size_t i = 0; i < run.candidates.size(); ++i)
    if (!run.candidates[i].aliases.empty() || run.candidates[i].technique != Technique::lp) named.push_back(entry(i));
  j["named"] = named;
  const std::vector<std::size_t> order = ranking_order(run);
  json best = json::array();
  for (std::size_t k = 0; k < std::min<std::size_t>(20, order.size()); ++k) best.push_back(entry(order[k]));
  j["best"] = best;

  std::int64_t singular = 0, failures = 0, fallbacks = 0, lps_total = 0, lp_total = 0;
  for (std::size_t i = 0; i < run.results.size(); ++i) lp_total += run.candidates[i].technique == Technique::lp ? 1 : 0;
  for (const CandidateResult& r : run.results) {
    singular += r.singular ? 1 : 0;
    failures += r.failures();
    fallbacks += r.fallbacks();
    lps_total += r.lps();
  }
  j["candidates"] = {
      {"total", run.candidates.size()}, {"lp", lp_total},          {"ranked_m", reference_m(run)},
      {"ranked", errors.size()},        {"singular", singular},    {"resumed_from_checkpoint", run.resumed},
      {"lp_glpk_fallbacks", fallbacks}, {"lp_failures", failures}, {"lps", lps_total}};
  if (!errors.empty())
    j["candidates"]["lp_error"] = {
        {"best", errors.front()}, {"median", errors[errors.size() / 2]}, {"worst", errors.back()}};

  // Throughput of the computation in this run (not of candidates read from the checkpoint).
  std::int64_t lps = 0, threads = 0;
  double slowest = 0.0, core_seconds = 0.0;
  json ranks = json::array();
  for (const RankTiming& t : run.ranks) {
    lps += t.lps;
    threads += t.threads;
    slowest = std::max(slowest, t.seconds);
    core_seconds += t.seconds * t.threads;
    ranks.push_back({{"rank", t.rank},
                     {"threads", t.threads},
                     {"candidates", t.candidates},
                     {"lps", t.lps},
                     {"seconds", t.seconds},
                     {"lps_per_second", t.seconds > 0 ? double(t.lps) / t.seconds : 0.0}});
  }
  const double per_core = core_seconds > 0 ? double(lps) / core_seconds : 0.0;
  j["timing"] = {{"ranks", run.size},
                 {"threads_total", threads},
                 {"stack_seconds", run.stack_seconds},
                 {"evaluation_seconds", slowest},
                 {"total_seconds", run.total_seconds},
                 {"lps_computed", lps},
                 {"lps_per_second", slowest > 0 ? double(lps) / slowest : 0.0},
                 {"lps_per_second_per_core", per_core},
                 {"per_rank", ranks}};
  if (per_core > 0) {
    const double core_hours = kPaperLpEvaluations / per_core / 3600.0;
    j["projection"] = {
        {"note", "the 2015 paper's 392e9 LP evaluations at this run's LPs per second per core (the LP size, i.e. "
                 "the grid and m, and the share of warm starts decide the rate)"},
        {"paper_lp_evaluations", kPaperLpEvaluations},
        {"core_hours", core_hours},
        {"hours_on_16_cores", core_hours / 16},
        {"hours_on_128_cores", core_hours / 128},
        {"hours_on_1024_cores", core_hours / 1024}};
    if (lps_total > 0 && lp_total > 0) {
      const double lps_per_candidate = double(lps_total) / double(lp_total);
      j["projection"]["all4_this_stack_core_hours"] = lps_per_candidate * 66045.0 / per_core / 3600.0;
    }
  }
  return j;
}

void write_report(const RunResult& run, const RunSettings& settings, const fs::path& dir) {
  // results.csv
  std::string table = "index,name,technique,m,aliases,functions,error";
  for (const std::string& s : run.scene_names) table += "," + csv_quoted("error " + s);
  table += ",max_error,fragments,lps,glpk_fallbacks,failures,iterations,cold_starts\n";
  for (std::size_t i = 0; i < run.results.size(); ++i) {
    const Candidate& c = run.candidates[i];
    const CandidateResult& r = run.results[i];
    double max_error = 0.0;
    std::int64_t fragments = 0, iterations = 0, cold = 0;
    for (const SceneSums& s : r.scenes) {
      max_error = std::max(max_error, s.max_error);
      fragments += s.fragments, iterations += s.iterations, cold += s.cold;
    }
    table += fmt::format("{},{},{},{},{},{},{}", i, csv_quoted(c.name), to_string(c.technique), c.m(),
                         csv_quoted(join(c.aliases, ";")), csv_quoted(formulas(c)),
                         r.singular ? "singular" : number(r.error()));
    for (const SceneSums& s : r.scenes) table += "," + (r.singular ? std::string("singular") : number(s.error()));
    table += fmt::format(",{},{},{},{},{},{},{}\n", number(max_error), fragments, r.lps(), r.fallbacks(), r.failures(),
                         iterations, cold);
  }
  write_text(dir / "results.csv", table);

  // ranking.csv
  const std::vector<double> errors = lp_errors(run);
  std::string ranking = "rank,index,name,technique,aliases,error,lp_rank,lp_share_better_percent\n";
  const std::vector<std::size_t> order = ranking_order(run);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    const CandidateResult& r = run.results[i];
    const double e = r.error();
    const std::int64_t lp_rank =
        r.singular ? 0 : std::int64_t(std::lower_bound(errors.begin(), errors.end(), e) - errors.begin()) + 1;
    ranking += fmt::format("{},{},{},{},{},{},{},{}\n", k + 1, i, csv_quoted(run.candidates[i].name),
                           to_string(run.candidates[i].technique), csv_quoted(join(run.candidates[i].aliases, ";")),
                           r.singular ? "singular" : number(e), lp_rank,
                           r.singular || errors.empty() ? std::string("nan")
                                                        : number(100.0 * double(lp_rank - 1) / double(errors.size())));
  }
  write_text(dir / "ranking.csv", ranking);

  // histogram.png
  std::vector<HistogramMark> marks;
  for (const auto& [label, name] : std::vector<std::pair<std::string, std::string>>{
           {"PCF", "pcf"}, {"VSM", "vsm"}, {"ESM", "esm"}, {"MSM", "power4"}, {"TMSM", "trig4"}})
    if (const CandidateResult* r = find_named(run, name); r && !r->singular) marks.push_back({label, r->error()});
  write_histogram(dir / "histogram.png", errors, marks,
                  fmt::format("{} sets of {} functions, {} scene(s), {}x{} maps, {}-point grid", errors.size(),
                              reference_m(run), run.scene_names.size(), settings.stack.size, settings.stack.size,
                              settings.stack.grid));

  write_text(dir / "summary.json", summary(run, settings).dump(2) + "\n");
}

} // namespace msm::evaluate
