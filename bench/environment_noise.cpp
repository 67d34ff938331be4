// The environment effect's cost of a given noise, for its two ways of sampling the probe
// (ProbeSampling, src/reference/internal.h) in this one binary: per scene, a converged
// reference (the compensated sampling at --reference samples per pixel, its own seed), then
// each sampling at 16, 36, 64, ..., 1024 (squares: a whole jittered grid) samples per pixel against it. The relative RMSE of an
// image is the RMSE of its irradiance's luminance over the lit pixels divided by the reference's
// mean luminance; the reference's own noise counts against both. Printed per scene and
// sampling: the relative RMSE at each count, the samples needed for the target (log-log
// interpolation between the counts that bracket it; beyond them, 1/sqrt(N) from the last), the
// time per sample (render time over pixel-samples, all counts together; the runs of the two
// samplings alternate so that a busy machine slows both alike) and their product, the
// equal-noise time.
//
// msm_bench_environment_noise [--size W H] [--reference N] [--target RMSE] [--threads T] [scene...]
// (default: scenes/city_probe.json and scenes/sky_probe.json, 96 x 54, 4096, 0.01, all cores).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "internal.h"
#include "msm/reference/reference.h"
#include "msm/scene/scene.h"
#include "msm/shading.h"

namespace {

using namespace msm::reference;
using detail::ProbeSampling;

struct Options {
  int width = 96, height = 54, reference_samples = 4096, threads = 0;
  double target = 0.01;
  std::vector<std::string> scenes;
};

std::vector<double> luminance_of(const Result& r) {
  const auto& p = r.irradiance.pixels();
  std::vector<double> y(r.irradiance.pixel_count());
  for (std::size_t k = 0; k < y.size(); ++k)
    y[k] = double(msm::msm_luminance(glm::vec3(p[4 * k], p[4 * k + 1], p[4 * k + 2])));
  return y;
}

// Over the pixels the reference lights (the background has E = 0 in every image).
double relative_rmse(const std::vector<double>& image, const std::vector<double>& reference) {
  double squared = 0.0, sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < image.size(); ++k) {
    if (!(reference[k] > 0.0)) continue;
    squared += (image[k] - reference[k]) * (image[k] - reference[k]);
    sum += reference[k];
    ++n;
  }
  return n ? std::sqrt(squared / double(n)) / (sum / double(n)) : 0.0;
}

// The count where the error crosses `target`, from errors at increasing counts.
double samples_needed(const std::vector<int>& counts, const std::vector<double>& errors, double target) {
  for (std::size_t k = 1; k < counts.size(); ++k)
    if (errors[k] <= target) {
      if (errors[k - 1] <= target && k == 1) break; // below it from the first count on: extrapolate down
      const double slope = std::log(errors[k] / errors[k - 1]) / std::log(double(counts[k]) / counts[k - 1]);
      return counts[k - 1] * std::pow(target / errors[k - 1], 1.0 / slope);
    }
  const std::size_t last = errors[0] <= target ? 0 : counts.size() - 1;
  return counts[last] * std::pow(errors[last] / target, 2.0);
}

const char* name_of(ProbeSampling d) { return d == ProbeSampling::compensated ? "compensated" : "luminance"; }

void measure(const std::string& file, const Options& o) {
  const msm::scene::Scene scene = msm::scene::load_scene(file);
  Settings s;
  s.effect = Effect::environment;
  s.width = o.width;
  s.height = o.height;
  s.threads = o.threads;
  s.samples = o.reference_samples;
  s.seed = 1000003;
  detail::set_probe_sampling(ProbeSampling::compensated);
  const std::vector<double> reference = luminance_of(render(scene, s));
  const std::vector<int> counts = {16, 36, 64, 144, 256, 576, 1024}; // squares: fully stratified
  const ProbeSampling samplings[] = {ProbeSampling::luminance, ProbeSampling::compensated};
  std::vector<double> errors[2], seconds(2, 0.0), pixel_samples(2, 0.0);
  s.seed = 1;
  for (int count : counts)
    for (int d = 0; d < 2; ++d) {
      detail::set_probe_sampling(samplings[d]);
      s.samples = count;
      const Result r = render(scene, s);
      errors[d].push_back(relative_rmse(luminance_of(r), reference));
      seconds[d] += r.render_seconds;
      pixel_samples[d] += double(r.irradiance.pixel_count() - r.background_pixels) * count;
    }
  std::printf("%s (%d x %d, reference %d samples per pixel):\n", scene.name.c_str(), o.width, o.height,
              o.reference_samples);
  double cost[2];
  for (int d = 0; d < 2; ++d) {
    std::printf("  %-11s relative RMSE", name_of(samplings[d]));
    for (std::size_t k = 0; k < counts.size(); ++k) std::printf(" %d: %.4f", counts[k], errors[d][k]);
    const double needed = samples_needed(counts, errors[d], o.target);
    const double per_sample = seconds[d] / pixel_samples[d];
    cost[d] = needed * per_sample;
    std::printf("\n  %-11s %.0f samples for %.2g, %.1f ns per sample, %.1f us per pixel\n", name_of(samplings[d]),
                needed, o.target, per_sample * 1e9, cost[d] * 1e6);
  }
  std::printf("  equal-noise time: %.2fx less with the compensated sampling\n", cost[0] / cost[1]);
  std::fflush(stdout);
}

} // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--size" && i + 2 < argc) {
      o.width = std::atoi(argv[++i]);
      o.height = std::atoi(argv[++i]);
    } else if (a == "--reference" && more)
      o.reference_samples = std::atoi(argv[++i]);
    else if (a == "--target" && more)
      o.target = std::atof(argv[++i]);
    else if (a == "--threads" && more)
      o.threads = std::atoi(argv[++i]);
    else if (!a.empty() && a[0] != '-')
      o.scenes.push_back(a);
    else {
      std::fprintf(stderr, "usage: %s [--size W H] [--reference N] [--target RMSE] [--threads T] [scene...]\n",
                   argv[0]);
      return 2;
    }
  }
  if (o.scenes.empty()) o.scenes = {MSM_SCENES_DIR "/city_probe.json", MSM_SCENES_DIR "/sky_probe.json"};
  try {
    for (const std::string& file : o.scenes) measure(file, o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
