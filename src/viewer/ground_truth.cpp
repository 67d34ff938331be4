#include "ground_truth.h"

#include "msm/techniques.h"

#include <exception>
#include <utility>

namespace msm::viewer {

namespace {
// Thrown from the progress callback to stop the tracer (TBB cancels the loop and rethrows it).
struct Cancelled {};
} // namespace

GroundTruth::~GroundTruth() {
  cancel_ = true;
  if (worker_.joinable()) worker_.join();
}

void GroundTruth::start(scene::Scene scene, const render::RenderSettings& s, int samples) {
  if (running_) return;
  if (worker_.joinable()) worker_.join();
  if (!s.lights.empty()) scene.lights = s.lights;
  const Technique& t = render::find_rendered_technique(s.technique);
  reference::Settings rs;
  rs.width = s.width;
  rs.height = s.height;
  rs.samples = samples;
  rs.shadow_size = s.shadow_size;
  rs.filter_size = s.filter_size;
  rs.filter_sigma = s.filter_sigma;
  if (msm_technique_is_area_light(t.id)) {
    rs.effect = reference::Effect::soft;
    // The renderer's overrides: the ray tracer draws the light they make as the renderer does
    // (scene::overridden_light).
    if (s.light_extent_deg) rs.light_extent_deg = *s.light_extent_deg;
    if (s.light_height_deg) rs.light_height_deg = *s.light_height_deg;
  } else {
    rs.effect = reference::Effect::filtered;
  }
  // One thread: the device (lavapipe: the CPU) keeps the others, the frame time stays close.
  rs.threads = 1;
  rs.progress = [this](const reference::Progress& p) {
    if (cancel_) throw Cancelled{};
    rows_total_ = std::max<std::size_t>(p.rows_total, 1);
    rows_done_ = p.rows_done;
  };
  reference::validate(rs); // std::invalid_argument on this thread, before anything starts
  settings_ = s;
  error_.clear();
  rows_done_ = 0;
  running_ = true;
  worker_ = std::thread([this, scene = std::move(scene), rs] {
    std::optional<reference::Result> r;
    std::string error;
    try {
      r = reference::render(scene, rs);
    } catch (const std::exception& e) { error = e.what(); } catch (const Cancelled&) {
      error = "cancelled";
    }
    std::lock_guard lock(mutex_);
    result_ = std::move(r);
    error_ = error;
    if (result_) seconds_ = result_->build_seconds + result_->render_seconds;
    running_ = false;
  });
}

float GroundTruth::progress() const noexcept { return float(rows_done_) / float(rows_total_); }

std::optional<reference::Result> GroundTruth::take() {
  std::lock_guard lock(mutex_);
  return std::exchange(result_, std::nullopt);
}

} // namespace msm::viewer
