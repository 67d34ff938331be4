// The cost of running the mesh import in a child process (import_child.cpp): per file, the
// import in this process (Assimp and the conversion), through the child (fork, the same import,
// the result through a pipe, the parent's checks), and the serialization and checked
// deserialization alone. Files: the arguments after the benchmark's own options, or by default
// glmark2's bunny.obj and two glTF samples of assimp-testmodels.
//   msm_bench_import [--benchmark_...] [MESH...]
#include <filesystem>
#include <string>
#include <vector>

#include <sys/resource.h>

#include <benchmark/benchmark.h>

#include "internal.h"
#include "msm/scene/scene.h"

namespace {

namespace fs = std::filesystem;
using namespace msm::scene;

void in_process(benchmark::State& state, const fs::path& file) {
  for (auto _ : state) benchmark::DoNotOptimize(detail::import_model_in_process(file));
}

double children_cpu_seconds() {
  rusage usage{};
  ::getrusage(RUSAGE_CHILDREN, &usage);
  const auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// Counter child_cpu_ms: the children's CPU time per import (user + system, getrusage), beside
// this process's CPU time that the benchmark reports.
void in_child(benchmark::State& state, const fs::path& file) {
  const double before = children_cpu_seconds();
  for (auto _ : state) benchmark::DoNotOptimize(import_model(file));
  state.counters["child_cpu_ms"] = 1e3 * (children_cpu_seconds() - before) / double(state.iterations());
}

void round_trip(benchmark::State& state, const fs::path& file) {
  const std::vector<ModelPart> parts = detail::import_model_in_process(file);
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string wire = detail::serialize_model(parts);
    bytes = wire.size();
    benchmark::DoNotOptimize(detail::deserialize_model(wire, file));
  }
  state.counters["bytes"] = double(bytes);
}

} // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::vector<fs::path> files(argv + 1, argv + argc);
  if (files.empty())
    files = {"/usr/share/glmark2/models/bunny.obj",
             "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
             "/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb"};
  for (const fs::path& file : files) {
    if (!fs::is_regular_file(file)) continue;
    const std::string name = file.filename().string();
    benchmark::RegisterBenchmark(("import/in_process/" + name).c_str(), in_process, file)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("import/child/" + name).c_str(), in_child, file)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("import/serialize_and_check/" + name).c_str(), round_trip, file)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
