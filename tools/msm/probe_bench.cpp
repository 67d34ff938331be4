// The light-probe pipeline's benchmark (probe_bench.h).
#include "probe_bench.h"

#include "msm/image/io.h"
#include "msm/probe/device_probe.h"
#include "msm/util/statistics.h"
#include "msm/vk/timer.h"

#include <fmt/core.h>

#include <cmath>
#include <map>
#include <span>

namespace msm::tool {
namespace {

void write_text(const std::string& path, const std::string& text) {
  image::write_file_atomic(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

} // namespace

void bench_probe(const ProbeBench& o, const std::string& device_name, int frames, int warmup, const std::string& json,
                 const std::string& markdown) {
  if (o.sizes.empty() || o.lights.empty()) throw UsageError("--probe-sizes and --lights need a value each");
  for (int size : o.sizes)
    if (size < 1 || size > probe::kMaxDeviceCubeSize)
      throw UsageError(fmt::format("--probe-sizes: {} outside 1..{}", size, probe::kMaxDeviceCubeSize));
  for (int n : o.lights)
    if (n < 1 || n > probe::kMaxDeviceLights)
      throw UsageError(fmt::format("--lights: {} outside 1..{}", n, probe::kMaxDeviceLights));
  const bool sky = o.probe == "sky";
  probe::Panorama panorama;
  if (!sky) {
    try {
      panorama = probe::load_equirect(o.probe);
    } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
  }
  std::unique_ptr<vk::Context> ctx = open_device(device_name);
  fmt::print(stderr, "msm bench: light probe {} on {}, {} frames after {} warm-up\n", o.probe, ctx->info().name, frames,
             warmup);
  vk::GpuTimer timer(*ctx);
  struct Row {
    int size, lights;
    double cube, tables, cut;
  };
  std::vector<Row> rows;
  for (int size : o.sizes) {
    probe::DeviceProbe device(*ctx, size);
    // The sky is a cube map made on the host (no resampling pass); a panorama is resampled each run.
    if (sky)
      device.set_cube(probe::sky_probe(size));
    else
      device.set_panorama(panorama);
    for (int n : o.lights) {
      std::map<std::string, std::vector<double>> ms;
      for (int f = 0; f < warmup + frames; ++f) {
        device.run(n, 10.0f * float(f), &timer); // a new rotation every run, as per frame
        const vk::TimerResults t = timer.read();
        if (f < warmup) continue;
        for (const char* pass : {"probe_cube", "probe_tables", "probe_cut"}) ms[pass].push_back(t.total(pass));
      }
      rows.push_back(Row{size, n, sky ? 0.0 : util::median(ms["probe_cube"]), util::median(ms["probe_tables"]),
                         util::median(ms["probe_cut"])});
      const Row& r = rows.back();
      fmt::print(stderr, "  {}² {:>3} lights: cube {:.2f} ms, tables {:.2f} ms, cut {:.2f} ms\n", size, n, r.cube,
                 r.tables, r.cut);
    }
  }
  // Ratios against the first size and the first light count. The cube map and the tables do not
  // depend on the light count: per size, their median over the light counts.
  const auto per_size = [&](int size, double Row::*field) {
    std::vector<double> v;
    for (const Row& r : rows)
      if (r.size == size) v.push_back(r.*field);
    return util::median(v);
  };
  const auto cut_at = [&](int size, int n) {
    for (const Row& r : rows)
      if (r.size == size && r.lights == n) return r.cut;
    return 0.0;
  };
  const int base_size = o.sizes.front(), base_n = o.lights.front();
  std::string table = "| face | lights | cube ms | tables ms | cut ms | tables ratio | cube ratio | face area ratio | "
                      "cut ratio | lights ratio | log2 N ratio |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  nlohmann::json results = nlohmann::json::array();
  for (const Row& r : rows) {
    const double tables_ratio = per_size(r.size, &Row::tables) / per_size(base_size, &Row::tables);
    const double base_cube = per_size(base_size, &Row::cube);
    const double cube_ratio = base_cube > 0.0 ? per_size(r.size, &Row::cube) / base_cube : 0.0;
    const double area_ratio = double(r.size) * r.size / (double(base_size) * base_size);
    const double base_cut = cut_at(r.size, base_n);
    const double cut_ratio = base_cut > 0.0 ? r.cut / base_cut : 0.0;
    // log2 N against the first count's; 0 where that is one light (log2 1 = 0), as the ratios above do.
    const double lights_ratio = double(r.lights) / base_n,
                 log_ratio = base_n > 1 ? std::log2(double(r.lights)) / std::log2(double(base_n)) : 0.0;
    table += fmt::format(
        "| {}² | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.0f} | {:.2f} | {:.0f} | {:.2f} |\n", r.size,
        r.lights, r.cube, r.tables, r.cut, tables_ratio, cube_ratio, area_ratio, cut_ratio, lights_ratio, log_ratio);
    results.push_back({{"size", r.size},
                       {"lights", r.lights},
                       {"probe_cube_ms", r.cube},
                       {"probe_tables_ms", r.tables},
                       {"probe_cut_ms", r.cut},
                       {"tables_ratio", tables_ratio},
                       {"cube_ratio", cube_ratio},
                       {"area_ratio", area_ratio},
                       {"cut_ratio", cut_ratio},
                       {"lights_ratio", lights_ratio},
                       {"log2_ratio", log_ratio}});
  }
  fmt::print("{}", table);
  const nlohmann::json doc = {
      {"device", ctx->info().name}, {"probe", o.probe}, {"frames", frames}, {"warmup", warmup}, {"results", results}};
  if (!json.empty()) write_text(json, doc.dump(2) + "\n");
  if (!markdown.empty()) write_text(markdown, table);
}

} // namespace msm::tool
