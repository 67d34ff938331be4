// Per-frame image-based lighting on the device (probe_frames.h).
#include "probe_frames.h"

#include "msm/image/io.h"
#include "msm/probe/device_probe.h"
#include "msm/vk/commands.h"
#include "msm/vk/timer.h"

#include <fmt/core.h>

#include <chrono>
#include <span>

namespace msm::tool {

void check_probe_frames(const scene::Scene& scene, const ProbeFrames& o) {
  if (!scene.probe)
    throw UsageError(
        fmt::format("--probe-rotation-speed/--frames: scene '{}' has no light probe (its \"probe\" key)", scene.name));
  if (o.frames < 1) throw UsageError("--frames must be at least 1");
  if (scene.probe->size > probe::kMaxDeviceCubeSize)
    throw UsageError(fmt::format("the probe's size {} exceeds the device pipeline's {}", scene.probe->size,
                                 probe::kMaxDeviceCubeSize));
  // A cube-map cross cannot be turned (load_probe_file): refused before the device is opened.
  if (o.rotation_speed_deg != 0.0f && scene.probe->file != "sky") {
    probe::Panorama panorama;
    try {
      panorama = probe::load_equirect(scene.probe->file);
    } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
    if (panorama.width != 2 * panorama.height)
      throw UsageError(fmt::format("--probe-rotation-speed {}: {} is a cube-map cross, which cannot be rotated",
                                   o.rotation_speed_deg, scene.probe->file.string()));
  }
}

void render_probe_frames(const vk::Context& ctx, render::Renderer& renderer, const scene::Scene& scene,
                         const FrameOptions& frame, const std::vector<std::string>& techniques, const std::string& out,
                         const ProbeFrames& o) {
  const scene::ProbeLighting& p = *scene.probe;
  const bool sky = p.file == "sky";
  probe::DeviceProbe device(ctx, p.size);
  device.set_horizon_split(p.horizon_split); // the scene's probe checked its lights and size for it
  probe::Panorama panorama;
  if (!sky) {
    try {
      panorama = probe::load_equirect(p.file);
    } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
    if (panorama.width == 2 * panorama.height) {
      for (glm::vec3& t : panorama.rgb) t *= p.intensity;
      device.set_panorama(panorama);
    } else {
      // A cube-map cross (the scene's loader took it as one, 4:3 or 3:4): its faces box-filtered
      // on the host (load_probe) and uploaded once; it does not turn (check_probe_frames). The
      // device's resampling is for panoramas: it read a cross as one (wrong lights) before.
      try {
        device.set_cube(probe::load_probe(p.file.string(), p.size, 0.0f, p.intensity));
      } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
    }
  }
  // The directional lights that the scene has beside its probe come first and stay.
  const std::vector<scene::DirectionalLight> fixed(scene.lights.begin(),
                                                   scene.lights.begin() + std::ptrdiff_t(p.first_light));
  vk::GpuTimer timer(ctx);
  nlohmann::json list = nlohmann::json::array();
  for (int k = 0; k < o.frames; ++k) {
    const float rotation = p.rotation_deg + float(k) * o.rotation_speed_deg;
    const auto start = std::chrono::steady_clock::now();
    if (sky) {
      // The procedural sky is made as a cube map on the host (no panorama to resample): it is
      // uploaded each frame and the device's pipeline starts at the tables.
      probe::CubeMap cube = probe::sky_probe(p.size, rotation);
      for (auto& f : cube.faces)
        for (glm::vec3& t : f) t *= p.intensity;
      device.set_cube(cube);
    }
    const probe::DeviceCut cut = device.run(p.lights, rotation, &timer);
    std::vector<scene::DirectionalLight> lights = fixed;
    std::size_t sub_light_count = 0;
    if (probe::sub_lights_refine(p.lights, p.sub_lights)) {
      // Sub-lights: the same probe cut again into more regions (its cube and tables made again; not
      // in the timings below, in the wall time), grouped by the region each lies in.
      for (const probe::ProbeLight& pl : probe::with_sub_lights(cut, device.run(p.sub_lights, rotation))) {
        lights.push_back(scene::light_of_probe_light(pl));
        sub_light_count += pl.sub_lights.size();
      }
    } else {
      for (const MsmAreaLight& a : cut.lights) lights.push_back(scene::light_of_area_light(a));
    }
    const double probe_wall_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const vk::TimerResults times = timer.read();
    const double cube_ms = times.total("probe_cube"), tables_ms = times.total("probe_tables"),
                 cut_ms = times.total("probe_cut");
    nlohmann::json entry = {{"frame", k},
                            {"rotation_deg", rotation},
                            {"lights", cut.lights.size()},
                            {"sub_lights", sub_light_count},
                            {"probe_ms", {{"probe_cube", cube_ms}, {"probe_tables", tables_ms}, {"probe_cut", cut_ms}}},
                            {"probe_wall_ms", probe_wall_ms},
                            {"render_ms", nlohmann::json::object()}};
    std::string line;
    for (const std::string& name : techniques) {
      render::RenderSettings s = settings_for(frame, name);
      s.lights = lights;
      render::RenderResult result;
      try {
        result = renderer.render(s);
      } catch (const render::RenderError& e) { throw UsageError(e.what()); }
      write_render(out, fmt::format("{}-frame{:03}", name, k), result, render_json(s, scene, ctx, result));
      entry["render_ms"][name] = result.total_ms;
      line += fmt::format("  {} {:.2f} ms", name, result.total_ms);
    }
    fmt::print(stderr,
               "frame {:>3}/{}  rotation {:7.2f}°  {:>3} lights{}  probe GPU: cube {:.2f} ms, tables {:.2f} ms, cut "
               "{:.2f} ms ({:.1f} ms wall with upload and read-back) |{}\n",
               k + 1, o.frames, rotation, cut.lights.size(),
               sub_light_count ? fmt::format(" ({} sub-lights)", sub_light_count) : "", cube_ms, tables_ms, cut_ms,
               probe_wall_ms, line);
    list.push_back(entry);
  }
  const std::string text =
      nlohmann::json{{"scene", scene.name}, {"probe_size", p.size}, {"frames", list}}.dump(2) + "\n";
  image::write_file_atomic(std::filesystem::path(out) / "probe-frames.json",
                           std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  fmt::print(stderr, "wrote {}/probe-frames.json\n", out);
}

} // namespace msm::tool
