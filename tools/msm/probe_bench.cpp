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
  if (o.sizes.empty() || o.lights.empty()) throw UsageError("--probe-sizes and --probe-lights need a value each");
  for (int size : o.sizes)
    if (size < 1 || size > probe::kMaxDeviceCubeSize)
      throw UsageError(fmt::format("--probe-sizes: {} outside 1..{}", size, probe::kMaxDeviceCubeSize));
  for (int n : o.lights)
    if (n < 6 || n > probe::kMaxDeviceLights)
      throw UsageError(fmt::format("--probe-lights: {} outside 6..{}", n, probe::kMaxDeviceLights));
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
  nlohmann::json results = nlohmann::json::array();
  std::string table = "| face | lights | cube ms | tables ms | cut ms | tables / 64² tables | face area ratio | cut / "
                      "cut at first N | log2 N ratio |\n|---|---|---|---|---|---|---|---|---|\n";
  std::map<int, double> tables_at_size;
  for (int size : o.sizes) {
    probe::DeviceProbe device(*ctx, size);
    // The sky is a cube map made on the host (no resampling pass); a panorama is resampled each run.
    if (sky)
      device.set_cube(probe::sky_probe(size));
    else
      device.set_panorama(panorama);
    double first_cut = 0.0;
    for (std::size_t i = 0; i < o.lights.size(); ++i) {
      const int n = o.lights[i];
      std::map<std::string, std::vector<double>> ms;
      for (int f = 0; f < warmup + frames; ++f) {
        device.run(n, 10.0f * float(f), &timer); // a new rotation every run, as per frame
        const vk::TimerResults t = timer.read();
        if (f < warmup) continue;
        for (const char* pass : {"probe_cube", "probe_tables", "probe_cut"}) ms[pass].push_back(t.total(pass));
      }
      const double cube = sky ? 0.0 : util::median(ms["probe_cube"]), tables = util::median(ms["probe_tables"]),
                   cut = util::median(ms["probe_cut"]);
      if (i == 0) first_cut = cut;
      if (!tables_at_size.count(size)) tables_at_size[size] = tables;
      const int base = o.sizes.front();
      const double tables_ratio = tables / tables_at_size[base];
      const double area_ratio = double(size) * size / (double(base) * base);
      const double cut_ratio = cut / first_cut, log_ratio = std::log2(double(n)) / std::log2(double(o.lights[0]));
      table += fmt::format("| {}² | {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.0f} | {:.2f} | {:.2f} |\n", size, n,
                           cube, tables, cut, tables_ratio, area_ratio, cut_ratio, log_ratio);
      results.push_back({{"size", size},
                         {"lights", n},
                         {"probe_cube_ms", cube},
                         {"probe_tables_ms", tables},
                         {"probe_cut_ms", cut},
                         {"tables_ratio", tables_ratio},
                         {"area_ratio", area_ratio},
                         {"cut_ratio", cut_ratio},
                         {"log2_ratio", log_ratio}});
      fmt::print(stderr, "  {}² {:>3} lights: cube {:.2f} ms, tables {:.2f} ms, cut {:.2f} ms\n", size, n, cube, tables,
                 cut);
    }
  }
  fmt::print("{}", table);
  const nlohmann::json doc = {
      {"device", ctx->info().name}, {"probe", o.probe}, {"frames", frames}, {"warmup", warmup}, {"results", results}};
  if (!json.empty()) write_text(json, doc.dump(2) + "\n");
  if (!markdown.empty()) write_text(markdown, table);
}

} // namespace msm::tool
