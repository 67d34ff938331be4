// Cost of generating blue noise (src/noise): one void-and-cluster run (one thread) at the sizes the
// tests use, and the renderer's whole set as the build generates it (TBB, every core).
#include "msm/noise/blue_noise.h"

#include <benchmark/benchmark.h>

namespace {

void void_and_cluster(benchmark::State& state) {
  const int size = int(state.range(0));
  std::uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(msm::noise::void_and_cluster_ranks(size, 1.9, seed++));
}
BENCHMARK(void_and_cluster)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

void renderer_set(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(msm::noise::generate_blue_noise(msm::noise::BlueNoiseParams{}));
}
BENCHMARK(renderer_set)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
