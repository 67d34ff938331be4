// `msm evaluate`: the 2015 framework for choosing shadow-map data (msm::evaluate): every fragment
// of the depth-peeled stacks of some scenes through the sharp LP bound of every candidate basis,
// against PCF; writes DIR/results.csv, ranking.csv, histogram.png and summary.json, and keeps a
// checkpoint in DIR/checkpoint to resume from. Runs alone (threads) or under mpirun (ranks).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "commands.h"
#include "msm/evaluate/functions.h"
#include "msm/evaluate/mpi.h"
#include "msm/evaluate/report.h"
#include "msm/evaluate/run.h"
#include "msm/evaluate/run_internals.h"
#include "msm/util/progress.h"
#include "msm/util/text.h"
#include "usage.h"
#include "vocabulary.h"

namespace msm::tool {
namespace {

using namespace msm::evaluate;

std::vector<std::string> split_list(const std::vector<std::string>& items) {
  std::vector<std::string> out;
  for (const std::string& item : items)
    for (std::string& part : util::split_nonempty(item, ',')) out.push_back(std::move(part));
  return out;
}

class ProgressBar {
 public:
  ProgressBar(int rank, int size) : rank_(rank), size_(size) {}
  void operator()(const Progress& p) {
    const std::string detail = fmt::format("{}/{} candidates{}  ", p.done, p.total,
                                           size_ > 1 ? fmt::format(" (rank {} of {})", rank_, size_) : "");
    fmt::print(stderr, "\r{}",
               util::progress_bar("msm evaluate", std::size_t(p.done), std::size_t(p.total), p.seconds, 30, detail));
    if (p.done == p.total) fmt::print(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  int rank_, size_;
};

void print_summary(const RunResult& run, const nlohmann::json& s, const std::string& out) {
  const auto& timing = s["timing"];
  fmt::print("msm evaluate: {} candidates ({} from the checkpoint) on {} scene(s) in {:.1f} s ({} rank(s), {} "
             "thread(s)): {} LPs, {:.0f} LPs/s, {:.0f} per core\n",
             run.candidates.size(), run.resumed, run.scene_names.size(), timing["total_seconds"].get<double>(),
             run.size, timing["threads_total"].get<long long>(), timing["lps_computed"].get<long long>(),
             timing["lps_per_second"].get<double>(), timing["lps_per_second_per_core"].get<double>());
  for (const auto& st : s["stacks"])
    fmt::print("  stack {}: {} fragments ({} receive light, {} of them fully lit), up to {} layers\n",
               st["scene"].get<std::string>(), st["fragments"].get<long long>(),
               st["counted_fragments"].get<long long>(), st["lit_fragments"].get<long long>(),
               st["max_layers"].get<long long>());
  const long long ranked = s["candidates"]["ranked"].get<long long>();
  const int ranked_m = s["candidates"]["ranked_m"].get<int>();
  const auto row = [&](const nlohmann::json& e) {
    const std::string error =
        e["error"].is_null() ? "singular" : fmt::format("{:.4f}%", 100.0 * e["error"].get<double>());
    std::string name = e["name"].get<std::string>();
    if (!e["aliases"].empty()) name += " (" + e["aliases"][0].get<std::string>() + ")";
    const std::string rank = e.contains("lp_rank")
                                 ? fmt::format("rank {} of {} (top {:.1f}%)", e["lp_rank"].get<long long>(), ranked,
                                               e["lp_percentile"].get<double>())
                                 : "";
    fmt::print("  {:<50} {:>9}  {}\n", name, error, rank);
  };
  if (!s["named"].empty()) {
    fmt::print("named (ranked among the {} sets of {} functions):\n", ranked, ranked_m);
    for (const auto& e : s["named"]) row(e);
  }
  fmt::print("best:\n");
  for (std::size_t k = 0; k < std::min<std::size_t>(10, s["best"].size()); ++k) row(s["best"][k]);
  fmt::print("Wrote {0}/results.csv, {0}/ranking.csv, {0}/histogram.png, {0}/summary.json\n", out);
}

} // namespace

void add_evaluate(CLI::App& app) {
  struct Options {
    std::vector<std::string> scenes{"fence,railing,stair,column,models,pillar_wall"};
    std::string candidates = "named", out = "out/evaluate";
    StackSettings stack;
    int threads = 0;
    long long stop_after = -1;
    bool solve_lit = false, fresh = false, progress = false, json = false, list_functions = false;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "evaluate", "The 2015 evaluation of shadow-map data: every fragment of depth-peeled shadow-map stacks through "
                  "the sharp LP bound of each candidate basis, against PCF (threads, or MPI ranks under mpirun)");
  add_term(cmd, "--scene", opt->scenes,
           "; several, comma-separated or repeated (default fence,railing,stair,column,models,pillar_wall)");
  cmd->add_option("--candidates", opt->candidates,
                  "Candidate list: named | all:K | sample:K:N[:SEED] | f1+f2+.. | power4, trig4, vsm, esm, .. "
                  "(comma-separated; default named; --functions lists the 37 functions)");
  add_term(cmd, "--out", opt->out, " (default out/evaluate)");
  add_term(cmd, "--shadow-size", opt->stack.size, " (default 128)");
  add_deprecated_option(cmd, "--size", "--shadow-size", opt->stack.size);
  cmd->add_option("--grid", opt->stack.grid, "Depth grid points on [0,1] (default 1025)");
  add_term(cmd, "--filter-size", opt->stack.filter_taps, " (default 9)");
  add_term(cmd, "--filter-sigma", opt->stack.filter_sigma, " (default 2.4)");
  cmd->add_option("--max-layers", opt->stack.max_layers, "Surfaces kept per texel (default 64)");
  cmd->add_option("--max-bias", opt->stack.max_bias,
                  "Cap of the receiver-plane depth bias in depth units (default 1: none)");
  add_term(cmd, "--threads", opt->threads, " per rank (default: the cores divided among the ranks)");
  cmd->add_flag("--solve-lit", opt->solve_lit, "Also send fully lit fragments through the LP (their bound is 0)");
  cmd->add_flag("--fresh", opt->fresh, "Discard an existing checkpoint in --out instead of resuming from it");
  add_term_flag(cmd, "--progress", opt->progress);
  add_term_flag(cmd, "--json", opt->json, ": summary.json instead of the text summary");
  cmd->add_flag("--functions", opt->list_functions, "List the 37 candidate functions and exit");
  cmd->add_option("--stop-after", opt->stop_after, "Testing: end abruptly after N candidates of this rank")->group("");
  cmd->callback([opt] {
    if (opt->list_functions) {
      for (const CandidateFunction& f : candidate_functions())
        fmt::print("{:<8} {:<22} {}\n", f.name, f.formula, f.family);
      return;
    }
    RunSettings settings;
    settings.scenes = split_list(opt->scenes);
    settings.candidates = opt->candidates;
    settings.out = opt->out;
    settings.stack = opt->stack;
    settings.threads = opt->threads;
    settings.evaluate.solve_lit = opt->solve_lit;
    settings.fresh = opt->fresh;
    evaluate::set_stop_after(opt->stop_after);

    const bool under_mpi = launched_by_mpi();
    if (under_mpi && !mpi_supported())
      throw UsageError("msm was started by an MPI launcher but built without MPI support (install libopenmpi-dev "
                       "and reconfigure)");
    std::unique_ptr<Communicator> comm = under_mpi ? mpi_world() : single_process();
    const int rank = comm->rank(), size = comm->size();
    ProgressBar bar(rank, size);
    std::function<void(const Progress&)> progress;
    if (rank == 0 && (opt->progress || ::isatty(::fileno(stderr))))
      progress = bar;
    else if (rank == 0) // a log: a line per tenth once the run has taken 2 s
      progress = [lines =
                      std::make_shared<msm::util::ProgressLines>("msm evaluate: ", " candidates")](const Progress& p) {
        if (auto line = lines->next(std::size_t(p.done), std::size_t(p.total), p.seconds))
          fmt::print(stderr, "{}\n", *line);
      };
    try {
      const RunResult run = run_evaluation(settings, *comm, progress);
      if (rank == 0) {
        write_report(run, settings, settings.out);
        const nlohmann::json s = summary(run, settings);
        if (opt->json)
          fmt::print("{}\n", s.dump(2));
        else
          print_summary(run, s, opt->out);
      }
    } catch (const std::invalid_argument& e) {
      // The same error on every rank at the same point (run.h): end normally, rank 0 says why.
      if (size == 1) throw UsageError(e.what());
      // Rank 0 says it before any rank exits: the launcher kills the job at the first non-zero
      // exit, which lost rank 0's message when another rank ended first (seen in a fresh clone).
      if (rank == 0) {
        fmt::print(stderr, "msm: error: {}\n", e.what());
        std::fflush(stderr);
      }
      comm->barrier();
      comm.reset(); // MPI_Finalize
      std::exit(kExitFailure);
    } catch (const std::exception& e) {
      if (size > 1) {
        fmt::print(stderr, "msm: error: rank {} of {}: {}\n", rank, size, e.what());
        std::fflush(stderr);
        mpi_abort(2); // the other ranks may wait in a collective
      }
      throw;
    }
  });
}

} // namespace msm::tool
