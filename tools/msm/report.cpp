// `msm report`: runs a declared suite (report_suite.h) and writes DIR/results.json (every figure with
// the device, driver, build, settings and command that produced it; docs/results.schema.json), the
// images it shows and, by the page generator (report_page.py: matplotlib charts and the HTML),
// DIR/index.html. `msm report --compare A/results.json B/results.json` writes the page of two runs.
#include "light_kinds.h"
#include "reference_look.h"
#include "render_common.h"
#include "report_suite.h"
#include "report_tests.h"
#include "vocabulary.h"

#include "msm/image/compose.h"
#include "msm/image/metrics.h"
#include "msm/reference/reference.h"
#include "msm/techniques.h"
#include "msm/util/limits.h"
#include "msm/util/output_dir.h"
#include "msm/util/statistics.h"
#include "msm/version.h"
#include "msm/viewer/view_file.h"

#include <fmt/chrono.h>
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace msm::tool {
namespace {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

constexpr double kErrorRange = 0.1; // the difference shown at full colour in the error maps
constexpr int kInsetCount = 3;      // magnified windows per row, where the techniques differ most
constexpr int kInsetMagnification = 4;

struct ReportOptions {
  std::string suite = "quick";
  std::string device;
  std::string out = "msm-report";
  std::vector<std::string> overrides; // --set TECHNIQUE:NAME=VALUE
  std::vector<std::string> compare;   // two results.json
  bool no_page = false;
  std::string tests_from;   // the build directory of the suite's test executables ("": msm's own)
  bool no_tests = false;    // run no test executables: results.json without "tests"
  std::string update_tests; // a results.json whose "tests" are gathered again, nothing else run
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The first line a program prints, or "" where it cannot run (no git, not a checkout).
std::string first_line_of(const std::string& command) {
  std::string line;
  if (FILE* pipe = ::popen(command.c_str(), "r")) {
    char buffer[256];
    if (std::fgets(buffer, sizeof buffer, pipe)) line = buffer;
    ::pclose(pipe);
  }
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  return line;
}

// The build: msm's version, the source's commit where the source is a git checkout (with
// "-dirty" when it has changes), the build type and the compiler.
ordered_json build_json() {
  const std::string git = fmt::format("git -C '{}' ", MSM_SOURCE_DIR);
  std::string commit = first_line_of(git + "rev-parse HEAD 2>/dev/null");
  if (!commit.empty() && !first_line_of(git + "status --porcelain --untracked-files=no 2>/dev/null").empty())
    commit += "-dirty";
  return {{"version", fmt::format("{}.{}.{}", MSM_VERSION_MAJOR, MSM_VERSION_MINOR, MSM_VERSION_PATCH)},
          {"git_commit", commit},
          {"build_type", MSM_BUILD_TYPE},
          {"compiler", __VERSION__}};
}

ordered_json device_json(const vk::Context& ctx) {
  const vk::DeviceInfo& d = ctx.info();
  return {{"name", d.name},
          {"driver", d.driver_name},
          {"driver_info", d.driver_info},
          {"vulkan", fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(d.api_version), VK_API_VERSION_MINOR(d.api_version),
                                 VK_API_VERSION_PATCH(d.api_version))},
          {"cpu_device", d.type == VK_PHYSICAL_DEVICE_TYPE_CPU},
          {"description", d.describe()}};
}

ordered_json host_json() {
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  return {{"hostname", name}, {"hardware_threads", std::thread::hardware_concurrency()}};
}

std::string utc_now() { return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::time(nullptr))); }

// The command that reproduces the run.
std::string command_line(const ReportOptions& o) {
  std::string line = fmt::format("msm report --suite {} --out {}", o.suite, o.out);
  if (!o.device.empty()) line += " --device " + o.device;
  for (const std::string& s : o.overrides) line += " --set " + s;
  if (!o.tests_from.empty()) line += " --tests-from " + o.tests_from;
  if (o.no_tests) line += " --no-tests";
  if (!o.update_tests.empty()) line += " --update-tests " + o.update_tests;
  return line;
}

fs::path tests_dir(const ReportOptions& o) {
  return o.tests_from.empty() ? default_tests_dir() : fs::path(o.tests_from);
}

// results.json's "tests": the figures the suite's test executables record, with the command, the
// source and the device they came from. A run that failed is counted in `failed_runs`.
ordered_json test_figures_json(const Suite& suite, const ReportOptions& options, const ordered_json& build,
                               int& failed_runs) {
  const auto start = std::chrono::steady_clock::now();
  const std::string started = utc_now();
  const GatheredTests gathered =
      gather_test_figures(suite, tests_dir(options), options.device, fs::path(options.out) / "tests");
  failed_runs = gathered.failed_runs;
  return {{"command", command_line(options)}, {"started_utc", started},
          {"seconds", seconds_since(start)},  {"build", build},
          {"msm_device", options.device},     {"runs", gathered.runs}};
}

void write_text_file(const fs::path& path, const std::string& text) {
  try {
    image::FileSet files;
    files.add(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    files.commit();
  } catch (const image::ImageError& e) { throw UsageError(e.what()); }
}

void throw_if_tests_failed(int failed_runs, const ReportOptions& options) {
  if (failed_runs > 0)
    throw std::runtime_error(fmt::format("{} test run(s) failed: their figures are in \"tests\" with \"holds\": false "
                                         "where an assertion failed; the output of each run is in {}/tests/",
                                         failed_runs, options.out));
}

// The settings of one technique of a row: the row's size, its named parameters, then the
// command line's --set TECHNIQUE:NAME=VALUE for that technique.
render::RenderSettings technique_settings(const SuiteRow& row, const SuiteTechnique& technique,
                                          const ReportOptions& options) {
  FrameOptions frame;
  frame.settings.width = row.width;
  frame.settings.height = row.height;
  frame.settings.shadow_size = row.shadow_size;
  frame.settings.light_extent_deg = row.light_extent_deg;
  frame.parameters = technique.parameters;
  const std::string name(canonical_technique_name(technique.name));
  for (const std::string& o : options.overrides)
    if (o.substr(0, o.find(':')) == name) frame.parameters.push_back(o.substr(o.find(':') + 1));
  try {
    render::RenderSettings s = settings_for(frame, name);
    s.validate();
    return s;
  } catch (const render::RenderError& e) { throw UsageError(fmt::format("suite row {}: {}", row.id, e.what())); }
}

// --set names a technique some row of the suite measures, and an assignment.
void check_overrides(const Suite& suite, const ReportOptions& options) {
  for (const std::string& o : options.overrides) {
    const std::size_t colon = o.find(':');
    if (colon == std::string::npos || o.find('=') < colon)
      throw UsageError(
          fmt::format("--set {}: expected TECHNIQUE:NAME=VALUE (e.g. msm-hamburger-64:moment_bias=1e-4)", o));
    const std::string technique = o.substr(0, colon);
    bool measured = false;
    for (const SuiteRow& row : suite.rows)
      for (const SuiteTechnique& t : row.techniques) measured |= canonical_technique_name(t.name) == technique;
    if (!measured)
      throw UsageError(fmt::format("--set {}: suite '{}' measures no technique '{}'", o, suite.name, technique));
  }
}

reference::Settings truth_settings(const SuiteRow& row, const render::RenderSettings& frame) {
  reference::Settings rs;
  rs.effect = row.truth;
  rs.width = row.width;
  rs.height = row.height;
  rs.samples = row.samples;
  rs.shadow_size = row.shadow_size;
  rs.filter_size = frame.filter_size;
  rs.filter_sigma = frame.filter_sigma;
  if (row.light_extent_deg) rs.light_extent_deg = *row.light_extent_deg;
  return rs;
}

// The row's scene, under the row's light kind where it names one: a built-in, else a scene file of
// the source tree msm was built from (as the suite's test executables are the build's).
scene::Scene row_scene(const SuiteRow& row) {
  const std::vector<std::string> builtins = scene::builtin_scene_names();
  const bool builtin = std::find(builtins.begin(), builtins.end(), row.scene) != builtins.end();
  scene::Scene scene = load_scene_or_fail(builtin ? row.scene : (fs::path(MSM_SOURCE_DIR) / row.scene).string());
  if (!row.light_kind) return scene;
  scene::Scene lit = scene_under_light_kind(scene, *row.light_kind);
  lit.name = fmt::format("{} ({} light)", scene.name, scene::light_kind(*row.light_kind).name);
  return lit;
}

// Every technique's settings are valid, and the row's renders and truth within the limits shared
// with msm render and msm reference (msm/util/limits.h): UsageError naming the row otherwise.
void check_row(const SuiteRow& row, const ReportOptions& options) {
  const scene::Scene scene = row_scene(row);
  try {
    for (const SuiteTechnique& t : row.techniques) {
      const render::RenderSettings s = technique_settings(row, t, options);
      render::check_limits(s, scene.triangle_count(), scene.lights.size());
      reference::check_limits(truth_settings(row, s), scene.triangle_count());
    }
  } catch (const limits::LimitError& e) { throw UsageError(fmt::format("suite row {}: {}", row.id, e.what())); }
}

// What one technique measured on a row.
struct Measured {
  render::RenderSettings settings;
  render::RenderResult result;
  image::Image signal; // what the metrics compare with the truth's visibility
};

// The pass times of the result replaced by the median of `frames` more frames (the first frame
// pays for warming up).
void time_passes(render::Renderer& renderer, const render::RenderSettings& s, int frames,
                 render::RenderResult& result) {
  const std::vector<std::vector<render::PassTime>> timed = renderer.time_frames(s, frames);
  result.total_ms = 0;
  for (render::PassTime& p : result.passes) {
    std::vector<double> ms;
    for (const auto& f : timed)
      for (const render::PassTime& q : f)
        if (q.name == p.name) ms.push_back(q.ms);
    if (!ms.empty()) p.ms = util::median(ms);
    result.total_ms += p.ms;
  }
}

// A window of an image, each pixel shown as factor² pixels (nearest: the texels stay visible).
image::Image magnified_window(const image::Image& rgb, const image::Rect& r, int factor) {
  image::Image out(r.width * factor, r.height * factor, 3);
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = rgb.at(r.x + x / factor, r.y + y / factor, c);
  return out;
}

ordered_json metrics_object(const image::Metrics& m) {
  return {{"mae", m.mae},
          {"rmse", m.rmse},
          {"max_error", m.max_error},
          {"light_leaking", m.light_leaking},
          {"over_darkening", m.over_darkening},
          {"mean_error", m.mean_error},
          {"share_above_1pct", m.share_above_1pct},
          {"share_above_3pct", m.share_above_3pct},
          {"share_above_10pct", m.share_above_10pct},
          {"pixels", m.pixels}};
}

ordered_json technique_json(const Measured& m, const image::Metrics& metrics, const ordered_json& images) {
  const Technique& t = render::find_rendered_technique(m.settings.technique);
  ordered_json parameters = ordered_json::object();
  for (const Parameter* p : t.parameter_list()) parameters[std::string(p->name)] = m.settings.parameter_text(p->name);
  ordered_json passes = ordered_json::object();
  for (const render::PassTime& p : m.result.passes) passes[p.name] = p.ms;
  ordered_json settings = ordered_json::object();
  for (const std::string& key : viewer::setting_keys()) settings[key] = viewer::setting_json(m.settings, key);
  return {{"name", std::string(t.name)},
          {"description", std::string(t.description)},
          {"bits_per_texel", t.bits_per_texel},
          {"parameters", parameters},
          {"settings", settings},
          {"metrics", metrics_object(metrics)},
          {"gpu_ms", passes},
          {"gpu_ms_total", m.result.total_ms},
          {"warnings", m.result.warnings},
          {"images", images}};
}

// One row: the truth traced, every technique rendered, timed and measured; its images added to
// `files` under DIR/<row id>/, its figures returned.
ordered_json run_row(const vk::Context& ctx, const Suite& suite, const SuiteRow& row, const ReportOptions& options,
                     image::FileSet& files) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<render::RenderSettings> settings;
  for (const SuiteTechnique& t : row.techniques) settings.push_back(technique_settings(row, t, options));
  scene::Scene scene = row_scene(row);
  if (row.probe_lights) try {
      scene::set_probe_light_count(scene, *row.probe_lights);
    } catch (const scene::SceneError& e) { throw UsageError(fmt::format("suite row {}: {}", row.id, e.what())); }
  const reference::Settings rs = truth_settings(row, settings.front());
  fmt::print(stderr, "msm report: {} ({} {}x{}): ray tracing the {} truth, {} samples per pixel ...\n", row.id,
             scene.name, row.width, row.height, reference::to_string(row.truth), row.samples);
  const reference::Result truth = reference::render(scene, rs);
  const bool scattering = row.truth == reference::Effect::scattering;
  const bool environment = row.truth == reference::Effect::environment;
  // Scattering: every view ray counts (JCGT §5's visible fraction); otherwise the surfaces only.
  const image::Image mask =
      scattering ? image::Image(row.width, row.height, 1) : truth.visibility.channel("background");
  const image::Image truth_rgb =
      scattering ? image::tone_map(truth.radiance, {std::log2(settings.front().exposure), image::ToneCurve::aces})
                 : reference_look(truth, settings.front().exposure);
  // Environment: the luminance of the look (as msm demo's image-based-lighting part measures it).
  const image::Image reference = environment ? image::select_signal(truth_rgb) : truth.visibility.channel("visibility");

  render::Renderer renderer(ctx, scene);
  std::vector<Measured> measured;
  for (const render::RenderSettings& s : settings) {
    fmt::print(stderr, "msm report: {}: {} ...\n", row.id, s.technique);
    Measured m{s, {}, {}};
    try {
      renderer.check(s);
      m.result = renderer.render(s);
      time_passes(renderer, s, suite.timed_frames, m.result);
    } catch (const render::RenderError& e) { throw UsageError(fmt::format("{}: {}", row.id, e.what())); }
    m.signal = scattering    ? m.result.scattering.channel("visible_fraction")
               : environment ? image::select_signal(m.result.color)
                             : m.result.shadow.channel("visibility");
    measured.push_back(std::move(m));
  }

  const fs::path dir = fs::path(options.out) / row.id;
  fs::create_directories(dir);
  std::vector<image::Image> signals = {reference};
  for (const Measured& m : measured) signals.push_back(m.signal);
  const int side = std::max(16, row.width / 10);
  const std::vector<image::Rect> insets = image::find_difference_regions(signals, side, side, kInsetCount);
  auto add_insets = [&](const image::Image& rgb, const std::string& stem) {
    ordered_json names = ordered_json::array();
    for (std::size_t k = 0; k < insets.size(); ++k) {
      const std::string name = fmt::format("{}/{}-inset{}.png", row.id, stem, k);
      files.add_png(fs::path(options.out) / name, magnified_window(rgb, insets[k], kInsetMagnification));
      names.push_back(name);
    }
    return names;
  };
  files.add_png(dir / "truth.png", truth_rgb);
  ordered_json truth_images = {{"render", row.id + "/truth.png"}, {"insets", add_insets(truth_rgb, "truth")}};

  ordered_json techniques = ordered_json::array();
  const image::MetricOptions metric_options{.mask = &mask};
  for (const Measured& m : measured) {
    const image::Metrics metrics = image::compute_metrics(m.signal, reference, metric_options);
    const std::string& name = m.settings.technique;
    files.add_png(dir / (name + ".png"), m.result.color);
    files.add_png(dir / (name + "-error.png"), image::error_image(m.signal, reference, kErrorRange, metric_options));
    const ordered_json images = {{"render", fmt::format("{}/{}.png", row.id, name)},
                                 {"error", fmt::format("{}/{}-error.png", row.id, name)},
                                 {"insets", add_insets(m.result.color, name)}};
    techniques.push_back(technique_json(m, metrics, images));
  }
  ordered_json inset_rects = ordered_json::array();
  for (const image::Rect& r : insets)
    inset_rects.push_back({{"x", r.x}, {"y", r.y}, {"width", r.width}, {"height", r.height}});
  return {{"id", row.id},
          {"scene", scene.name},
          {"scene_source", scene.source.string()},
          {"triangles", scene.triangle_count()},
          {"width", row.width},
          {"height", row.height},
          {"shadow_size", row.shadow_size},
          {"truth",
           {{"effect", std::string(reference::to_string(row.truth))},
            {"samples", truth.samples},
            {"seconds", truth.build_seconds + truth.render_seconds},
            {"light_extent_deg", truth.light_extent_deg}, // as traced (soft)
            {"signal", scattering    ? "visible fraction of each view ray, every pixel"
                       : environment ? "luminance of the tone-mapped image, background excluded"
                                     : "visibility of the surfaces, background excluded"},
            {"probe_lights", scene.probe ? scene.probe->lights : 0},
            {"images", truth_images}}},
          {"error_range", kErrorRange},
          {"insets", inset_rects},
          {"inset_magnification", kInsetMagnification},
          {"techniques", techniques},
          {"seconds", seconds_since(start)}};
}

// Runs a program with its arguments (no shell), its output on ours; its exit status.
int run_program(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    ::execvp(argv[0], argv.data());
    std::fprintf(stderr, "msm report: cannot run %s\n", argv[0]);
    std::_Exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The page generator: Debian's Python with matplotlib (MSM_PYTHON overrides it).
void write_page(const std::vector<std::string>& results, const std::string& out) {
  const char* python = std::getenv("MSM_PYTHON");
  std::vector<std::string> args = {python && *python ? python : "/usr/bin/python3", MSM_REPORT_PAGE_SCRIPT};
  args.insert(args.end(), results.begin(), results.end());
  args.insert(args.end(), {"--schema", MSM_RESULTS_SCHEMA, "--out", out});
  const int status = run_program(args);
  if (status != 0)
    throw UsageError(fmt::format("the page generator ({}) failed (exit status {}); results.json is in {}",
                                 MSM_REPORT_PAGE_SCRIPT, status, out));
}

// --update-tests FILE: the suite's test figures gathered again into FILE (a results.json of the same
// suite), its other figures kept as they are.
void update_tests(const ReportOptions& options) {
  const Suite& suite = find_suite(options.suite);
  check_test_executables(suite, tests_dir(options));
  ordered_json results;
  try {
    std::ifstream in(options.update_tests);
    if (!in) throw UsageError(fmt::format("--update-tests {}: no such file", options.update_tests));
    results = ordered_json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw UsageError(fmt::format("--update-tests {}: not JSON: {}", options.update_tests, e.what()));
  }
  if (!results.is_object() || !results.contains("suite") || results["suite"].value("name", "") != suite.name)
    throw UsageError(
        fmt::format("--update-tests {}: not the results.json of suite '{}'", options.update_tests, suite.name));
  if (const auto problem = util::prepare_output_dir(options.out, "msm-report-probe"))
    throw UsageError(fmt::format("--out {}: {}", options.out, *problem));
  int failed_runs = 0;
  results["tests"] = test_figures_json(suite, options, build_json(), failed_runs);
  write_text_file(options.update_tests, results.dump(2) + "\n");
  fmt::print(stderr, "msm report: wrote the test figures into {}\n", options.update_tests);
  throw_if_tests_failed(failed_runs, options);
}

void run_suite(const ReportOptions& options) {
  const Suite& suite = find_suite(options.suite);
  check_overrides(suite, options);
  for (const SuiteRow& row : suite.rows) check_row(row, options); // refused before any work
  if (!options.no_tests) check_test_executables(suite, tests_dir(options));
  const auto start = std::chrono::steady_clock::now();
  const std::string started = utc_now();
  const ordered_json build = build_json();                        // the source as the run starts
  std::unique_ptr<vk::Context> ctx = open_device(options.device); // no device: no output directory either
  if (const auto problem = util::prepare_output_dir(options.out, "msm-report-probe"))
    throw UsageError(fmt::format("--out {}: {}", options.out, *problem));
  fmt::print(stderr, "msm report: suite '{}' ({} rows) on {}\n", suite.name, suite.rows.size(), ctx->info().name);
  image::FileSet files;
  ordered_json rows = ordered_json::array();
  for (const SuiteRow& row : suite.rows) rows.push_back(run_row(*ctx, suite, row, options, files));
  const ordered_json device = device_json(*ctx);
  ctx.reset(); // the tests open the device themselves
  int failed_runs = 0;
  const ordered_json tests =
      options.no_tests || suite.tests.empty() ? ordered_json() : test_figures_json(suite, options, build, failed_runs);
  ordered_json results = {
      {"schema_version", 1},
      {"suite", {{"name", suite.name}, {"description", suite.description}}},
      {"command", command_line(options)},
      {"started_utc", started},
      {"seconds", seconds_since(start)},
      {"device", device},
      {"host", host_json()},
      {"build", build},
      {"timing", fmt::format("GPU timestamps per pass, median of {} frames after the first", suite.timed_frames)},
      {"rows", rows}};
  if (!tests.is_null()) results["tests"] = tests;
  const std::string text = results.dump(2) + "\n";
  try {
    files.add(fs::path(options.out) / "results.json",
              {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    files.commit();
  } catch (const image::ImageError& e) { throw UsageError(e.what()); }
  fmt::print(stderr, "msm report: {:.1f} s; wrote {}/results.json\n", seconds_since(start), options.out);
  if (!options.no_page) write_page({(fs::path(options.out) / "results.json").string()}, options.out);
  throw_if_tests_failed(failed_runs, options);
}

} // namespace

void add_report(CLI::App& app) {
  auto opt = std::make_shared<ReportOptions>();
  auto* cmd = app.add_subcommand("report", "Run a declared suite of scenes x techniques against the ray-traced "
                                           "truth: DIR/results.json (every figure, device, build, settings) and "
                                           "DIR/index.html (images, error maps, insets, sortable tables, charts)");
  cmd->add_option("--suite", opt->suite, fmt::format("The suite: {}", fmt::join(suite_names(), ", ")))
      ->capture_default_str();
  add_term(cmd, "--out", opt->out)->capture_default_str();
  add_term(cmd, "--device", opt->device);
  cmd->add_option("--set", opt->overrides,
                  "A technique's parameter for every row that measures it, TECHNIQUE:NAME=VALUE (repeatable)")
      ->take_all();
  cmd->add_option("--compare", opt->compare,
                  "Two results.json (A B): the page of both runs side by side, differences highlighted; runs "
                  "nothing")
      ->expected(2);
  cmd->add_flag("--no-page", opt->no_page, "Write results.json and the images only");
  cmd->add_option("--tests-from", opt->tests_from,
                  fmt::format("The build directory whose test executables record the suite's test figures "
                              "(default: the one msm was built in, {})",
                              default_tests_dir().string()));
  cmd->add_flag("--no-tests", opt->no_tests, "Run no test executables: results.json without the test figures");
  cmd->add_option("--update-tests", opt->update_tests,
                  "A results.json of the suite: gather its test figures again (logs under --out) and replace them "
                  "there, its other figures kept; renders nothing");
  cmd->callback([opt, cmd] {
    if (!opt->compare.empty()) {
      for (const char* o :
           {"--suite", "--device", "--set", "--no-page", "--tests-from", "--no-tests", "--update-tests"})
        if (cmd->count(o) > 0) throw UsageError(fmt::format("--compare runs nothing: {} cannot go with it", o));
      for (const std::string& f : opt->compare)
        if (!fs::is_regular_file(f)) throw UsageError(fmt::format("--compare {}: no such file", f));
      if (const auto problem = util::prepare_output_dir(opt->out, "msm-report-probe"))
        throw UsageError(fmt::format("--out {}: {}", opt->out, *problem));
      write_page(opt->compare, opt->out);
      return;
    }
    if (!opt->update_tests.empty()) {
      for (const char* o : {"--set", "--no-page", "--no-tests"})
        if (cmd->count(o) > 0) throw UsageError(fmt::format("--update-tests renders nothing: {} cannot go with it", o));
      update_tests(*opt);
      return;
    }
    run_suite(*opt);
  });
}

} // namespace msm::tool
