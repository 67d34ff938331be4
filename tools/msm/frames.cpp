// Frame sequences of dynamic scenes: the probe's lights on the device, moving objects (frames.h).
#include "frames.h"

#include "msm/image/io.h"
#include "msm/probe/device_probe.h"
#include "msm/util/clock.h"
#include "msm/vk/commands.h"
#include "msm/vk/timer.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <span>

namespace msm::tool {

void check_frames(const scene::Scene& scene, const Frames& o) {
  if (o.rotation_speed_deg != 0.0f && !scene.probe)
    throw UsageError(
        fmt::format("--probe-rotation-speed: scene '{}' has no light probe (its \"probe\" key)", scene.name));
  if (!scene.probe && !scene.animated())
    throw UsageError(fmt::format("--frames: scene '{}' has neither a light probe (its \"probe\" key) nor moving "
                                 "objects (an object's \"motion\")",
                                 scene.name));
  if (o.frames < 1) throw UsageError("--frames must be at least 1");
  if (!scene.probe) return;
  if (scene.probe->size > probe::kMaxDeviceCubeSize)
    throw UsageError(fmt::format("the probe's size {} exceeds the device pipeline's {}", scene.probe->size,
                                 probe::kMaxDeviceCubeSize));
  // A cube-map cross or six faces cannot be turned (load_probe_file): refused before the device is
  // opened.
  if (o.rotation_speed_deg != 0.0f && probe::is_cube_faces_path(scene.probe->file))
    throw UsageError(fmt::format("--probe-rotation-speed {}: {} names six cube faces, which cannot be rotated",
                                 o.rotation_speed_deg, scene.probe->file.string()));
  if (o.rotation_speed_deg != 0.0f && scene.probe->file != "sky") {
    probe::Panorama panorama;
    try {
      panorama = probe::load_equirect(scene.probe->file);
    } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
    if (probe::picture_layout(panorama.width, panorama.height) != probe::PictureLayout::panorama)
      throw UsageError(fmt::format("--probe-rotation-speed {}: {} is a cube-map cross, which cannot be rotated",
                                   o.rotation_speed_deg, scene.probe->file.string()));
  }
}

namespace {

// The probe's side of a frame sequence: the device pipeline and the lights it makes each frame.
class ProbeSequence {
 public:
  ProbeSequence(const vk::Context& ctx, const scene::Scene& scene)
      : p_(*scene.probe), device_(ctx, p_.size), timer_(ctx) {
    device_.set_horizon_split(p_.horizon_split); // the scene's probe checked its lights and size for it
    if (p_.file == "sky") return;
    if (!probe::is_cube_faces_path(p_.file)) {
      probe::Panorama panorama;
      try {
        panorama = probe::load_equirect(p_.file);
      } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
      if (probe::picture_layout(panorama.width, panorama.height) == probe::PictureLayout::panorama) {
        for (glm::vec3& t : panorama.rgb) t *= p_.intensity;
        device_.set_panorama(panorama);
        return;
      }
    }
    // A cube-map cross (the scene's loader took it as one, 4:3 or 3:4) or six face files: the faces
    // box-filtered on the host (load_probe) and uploaded once; they do not turn (check_frames). The
    // device's resampling is for panoramas: it read a cross as one (wrong lights) before.
    try {
      device_.set_cube(probe::load_probe(p_.file.string(), p_.size, 0.0f, p_.intensity));
    } catch (const probe::ProbeError& e) { throw UsageError(e.what()); }
  }

  // The frame's lights: the probe's appended to `lights` (the scene's directional ones); fills the
  // frame's entry of frames.json and its part of the line.
  std::vector<scene::DirectionalLight> run(int k, const Frames& o, std::vector<scene::DirectionalLight> lights,
                                           nlohmann::json& entry, std::string& line) {
    const float rotation = p_.rotation_deg + float(k) * o.rotation_speed_deg;
    const auto start = std::chrono::steady_clock::now();
    if (p_.file == "sky") {
      // The procedural sky is made as a cube map on the host (no panorama to resample): it is
      // uploaded each frame and the device's pipeline starts at the tables.
      probe::CubeMap cube = probe::sky_probe(p_.size, rotation);
      for (auto& f : cube.faces)
        for (glm::vec3& t : f) t *= p_.intensity;
      device_.set_cube(cube);
    }
    const probe::DeviceCut cut = device_.run(p_.lights, rotation, &timer_);
    std::size_t sub_light_count = 0;
    if (probe::sub_lights_refine(p_.lights, p_.sub_lights)) {
      // Sub-lights: the same probe cut again into more regions (its cube and tables made again; not
      // in the timings below, in the wall time), grouped by the region each lies in.
      for (const probe::ProbeLight& pl : probe::with_sub_lights(cut, device_.run(p_.sub_lights, rotation))) {
        lights.push_back(scene::light_of_probe_light(pl));
        sub_light_count += pl.sub_lights.size();
      }
    } else {
      for (const MsmAreaLight& a : cut.lights) lights.push_back(scene::light_of_area_light(a));
    }
    const double wall_ms = util::ms_since(start);
    const vk::TimerResults times = timer_.read();
    const double cube_ms = times.total("probe_cube"), tables_ms = times.total("probe_tables"),
                 cut_ms = times.total("probe_cut");
    entry["rotation_deg"] = rotation;
    entry["lights"] = cut.lights.size();
    entry["sub_lights"] = sub_light_count;
    entry["probe_ms"] = {{"probe_cube", cube_ms}, {"probe_tables", tables_ms}, {"probe_cut", cut_ms}};
    entry["probe_wall_ms"] = wall_ms;
    line += fmt::format("  rotation {:7.2f}°  {:>3} lights{}  probe GPU: cube {:.2f} ms, tables {:.2f} ms, cut "
                        "{:.2f} ms ({:.1f} ms wall with upload and read-back)",
                        rotation, cut.lights.size(),
                        sub_light_count ? fmt::format(" ({} sub-lights)", sub_light_count) : "", cube_ms, tables_ms,
                        cut_ms, wall_ms);
    return lights;
  }

 private:
  const scene::ProbeLighting& p_;
  probe::DeviceProbe device_;
  vk::GpuTimer timer_;
};

} // namespace

void render_frames(const vk::Context& ctx, render::Renderer& renderer, const scene::Scene& scene,
                   const FrameOptions& frame, const std::vector<std::string>& techniques, const std::string& out,
                   const Frames& o) {
  std::optional<ProbeSequence> probe;
  if (scene.probe) probe.emplace(ctx, scene);
  // The directional lights that the scene has beside its probe come first and stay.
  const std::size_t fixed = scene.probe ? scene.probe->first_light : scene.lights.size();
  const std::vector<scene::DirectionalLight> fixed_lights(scene.lights.begin(),
                                                          scene.lights.begin() + std::ptrdiff_t(fixed));
  const std::size_t moving =
      std::ranges::count_if(scene.objects, [](const scene::Object& object) { return object.motion.has_value(); });
  const render::RenderSettings& f = frame.settings;
  const std::vector<std::string> warnings =
      scene::shadow_framing_warnings(scene, f.width, f.height, f.shadow_size, render::cascade_options(f, scene));
  nlohmann::json list = nlohmann::json::array();
  for (int k = 0; k < o.frames; ++k) {
    nlohmann::json entry = {{"frame", k}};
    std::string line;
    std::vector<scene::DirectionalLight> lights = fixed_lights;
    if (probe) lights = probe->run(k, o, std::move(lights), entry, line);
    if (moving) {
      const auto start = std::chrono::steady_clock::now();
      try {
        renderer.move_objects(scene::at_frame(scene, k));
      } catch (const render::RenderError& e) { throw UsageError(e.what()); }
      const double ms = util::ms_since(start);
      entry["objects_ms"] = ms;
      line += fmt::format("  {} moving object{} {:.2f} ms (moved on the host, uploaded)", moving, moving > 1 ? "s" : "",
                          ms);
    }
    line += " |";
    entry["render_ms"] = nlohmann::json::object();
    for (const std::string& name : techniques) {
      render::RenderSettings s = settings_for(frame, name);
      s.frame = frame.noise_frame.value_or(k); // a blue-noise layer of its own each frame
      s.lights = lights;
      render::RenderResult result;
      try {
        result = renderer.render(s);
      } catch (const render::RenderError& e) { throw UsageError(e.what()); }
      write_render(out, fmt::format("{}-frame{:03}", name, k), result, render_json(s, scene, k, warnings, ctx, result));
      entry["render_ms"][name] = result.total_ms;
      line += fmt::format("  {} {:.2f} ms", name, result.total_ms);
    }
    fmt::print(stderr, "frame {:>3}/{}{}\n", k + 1, o.frames, line);
    list.push_back(entry);
  }
  nlohmann::json summary = {{"scene", scene.name}, {"frames", list}};
  if (scene.probe) summary["probe_size"] = scene.probe->size;
  const std::string text = summary.dump(2) + "\n";
  image::write_file_atomic(std::filesystem::path(out) / "frames.json",
                           std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  fmt::print(stderr, "wrote {}/frames.json\n", out);
}

} // namespace msm::tool
