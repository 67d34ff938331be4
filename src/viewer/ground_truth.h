// The ray-traced ground truth of the viewer's current view (msm::reference), computed on one
// worker thread so that the window stays responsive: the filtered effect with the view's shadow
// map and kernel, or the soft effect for the area-light techniques.
#pragma once

#include "msm/reference/reference.h"
#include "msm/render/renderer.h"

#include <atomic>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace msm::viewer {

class GroundTruth {
 public:
  GroundTruth() = default;
  ~GroundTruth(); // cancels a running computation (at its next progress report) and waits for it
  GroundTruth(const GroundTruth&) = delete;
  GroundTruth& operator=(const GroundTruth&) = delete;

  // `scene` already carries the view's camera; its lights become settings.lights where given.
  void start(scene::Scene scene, const render::RenderSettings& settings, int samples);
  bool running() const noexcept { return running_; }
  float progress() const noexcept; // 0..1
  // The finished result (once), or nullopt; error() says why a computation failed.
  std::optional<reference::Result> take();
  const std::string& error() const noexcept { return error_; }
  // The settings the running or last computation was started with.
  const render::RenderSettings& settings() const noexcept { return settings_; }
  double seconds() const noexcept { return seconds_; }

 private:
  std::thread worker_;
  std::atomic<bool> running_{false}, cancel_{false};
  std::atomic<std::size_t> rows_done_{0}, rows_total_{1};
  std::mutex mutex_;
  std::optional<reference::Result> result_;
  std::string error_;
  render::RenderSettings settings_;
  double seconds_ = 0;
};

} // namespace msm::viewer
