// A whole evaluation (`msm evaluate`): stacks of several scenes, a candidate list, the work split
// over MPI ranks and threads, a checkpoint to resume from, and the results gathered at rank 0.
//
// Work: the unit is one candidate on every stack (its error needs them all), so a candidate's
// sums never depend on how the work was split: one process with threads, or any number of ranks,
// give the same bits. Rank 0 traces the scenes and broadcasts the stacks (so every rank sees the
// same bits whatever its CPU), the candidates still to do are dealt out round-robin over the ranks,
// and in each rank threads take them one at a time.
//
// Checkpoint (DIR/checkpoint): run.json holds the fingerprint of the run (every stack, the
// candidate list, the options that change results); each rank appends one line per finished
// candidate to rank<r>.jsonl (written and fsynced before the next). A restarted run with the same
// fingerprint reads every rank<*>.jsonl (any rank count) and skips those candidates; a half-written
// last line (a killed process) is ignored. A different fingerprint is an error unless `fresh`,
// which deletes the old checkpoint. For a resumed run to see every rank's work the output
// directory must be on a file system all ranks share (rank 0 reads the checkpoint).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "msm/evaluate/candidates.h"
#include "msm/evaluate/communicator.h"
#include "msm/evaluate/evaluate.h"
#include "msm/evaluate/stack.h"

namespace msm::evaluate {

struct RunSettings {
  std::vector<std::string> scenes; // built-in names or scene files
  StackSettings stack;
  std::string candidates = "named";
  std::filesystem::path out;
  int threads = 0; // per rank; 0: the machine's cores divided among its ranks
  EvaluateOptions evaluate;
  bool fresh = false; // discard an existing checkpoint instead of resuming
};

struct CandidateResult {
  std::int64_t index = 0;
  bool singular = false; // the basis is linearly dependent on the grid: no error
  std::vector<SceneSums> scenes;
  // The mean over the scenes of each scene's mean error (every scene weighs the same).
  double error() const;
  std::int64_t lps() const;
  std::int64_t fallbacks() const;
  std::int64_t failures() const;
};

struct RankTiming {
  int rank = 0, threads = 0;
  std::int64_t candidates = 0, lps = 0; // computed here (not read from the checkpoint)
  double seconds = 0.0;                 // wall time of the computation
};

struct Progress {
  std::int64_t done = 0, total = 0; // candidates of this rank
  double seconds = 0.0;
};

struct RunResult {
  std::vector<Candidate> candidates;
  std::vector<CandidateResult> results; // rank 0: one per candidate, by index; elsewhere empty
  std::vector<std::string> scene_names;
  std::vector<StackStats> stacks;
  std::vector<std::uint64_t> stack_fingerprints;
  std::int64_t resumed = 0; // candidates read from the checkpoint
  std::vector<RankTiming> ranks;
  double stack_seconds = 0.0, total_seconds = 0.0;
  int rank = 0, size = 1;
};

// Runs on every rank (collective). Throws std::invalid_argument for bad settings, candidates,
// scenes, output directories or checkpoints: on every rank alike and at the same point, so each can
// end normally. Anything else (std::runtime_error: an I/O failure during the work, on one rank) may
// leave the other ranks waiting: abort them (mpi_abort). `progress` is called on rank 0 from its
// worker threads, one call at a time.
RunResult run_evaluation(const RunSettings& settings, Communicator& communicator,
                         const std::function<void(const Progress&)>& progress = {});

} // namespace msm::evaluate
