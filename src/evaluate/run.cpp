// A whole evaluation over ranks and threads, with its checkpoint (run.h).
#include "msm/evaluate/run.h"
#include "msm/evaluate/run_internals.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "msm/scene/scene.h"
#include "msm/util/clock.h"
#include "msm/util/output_dir.h"

namespace msm::evaluate {

double CandidateResult::error() const {
  if (singular || scenes.empty()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  for (const SceneSums& s : scenes) sum += s.error();
  return sum / double(scenes.size());
}

std::int64_t CandidateResult::lps() const {
  std::int64_t sum = 0;
  for (const SceneSums& s : scenes) sum += s.lps;
  return sum;
}

std::int64_t CandidateResult::fallbacks() const {
  std::int64_t sum = 0;
  for (const SceneSums& s : scenes) sum += s.fallbacks;
  return sum;
}

std::int64_t CandidateResult::failures() const {
  std::int64_t sum = 0;
  for (const SceneSums& s : scenes) sum += s.failures;
  return sum;
}

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

using util::seconds_since;

std::unique_ptr<Communicator> make_single();

// ---- Byte packing ---------------------------------------------------------------------------

struct Packer {
  std::vector<char> bytes;
  template <typename T>
  void put(T value) {
    const char* p = reinterpret_cast<const char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void put_string(const std::string& s) {
    put(std::uint64_t(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
};

struct Unpacker {
  const std::vector<char>& bytes;
  std::size_t at = 0;
  template <typename T>
  T get() {
    if (bytes.size() - at < sizeof(T)) throw std::runtime_error("evaluate: truncated message between ranks");
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return value;
  }
  std::string get_string() {
    const auto size = get<std::uint64_t>();
    if (bytes.size() - at < size) throw std::runtime_error("evaluate: truncated message between ranks");
    std::string s(bytes.data() + at, std::size_t(size));
    at += std::size_t(size);
    return s;
  }
};

void put_sums(Packer& p, const SceneSums& s) {
  p.put(s.error_sum), p.put(s.max_error), p.put(s.fragments), p.put(s.lps), p.put(s.fallbacks), p.put(s.failures),
      p.put(s.iterations), p.put(s.cold);
}

SceneSums get_sums(Unpacker& u) {
  SceneSums s;
  s.error_sum = u.get<double>();
  s.max_error = u.get<double>();
  s.fragments = u.get<std::int64_t>();
  s.lps = u.get<std::int64_t>();
  s.fallbacks = u.get<std::int64_t>();
  s.failures = u.get<std::int64_t>();
  s.iterations = u.get<std::int64_t>();
  s.cold = u.get<std::int64_t>();
  return s;
}

// Runs `work` on rank 0 and hands its bytes, or its exception, to every rank: the other ranks never
// wait in a collective that rank 0 will not reach.
std::vector<char> on_rank0(Communicator& comm, const std::function<std::vector<char>()>& work) {
  std::vector<char> message;
  if (comm.rank() == 0) {
    char status = 0;
    std::string error;
    std::vector<char> payload;
    try {
      payload = work();
    } catch (const std::invalid_argument& e) { status = 1, error = e.what(); } catch (const std::exception& e) {
      status = 2, error = e.what();
    }
    message.push_back(status);
    if (status == 0)
      message.insert(message.end(), payload.begin(), payload.end());
    else
      message.insert(message.end(), error.begin(), error.end());
  }
  if (comm.size() > 1) comm.broadcast(message);
  if (message.empty()) throw std::runtime_error("evaluate: empty message from rank 0");
  const std::string text(message.begin() + 1, message.end());
  if (message[0] == 1) throw std::invalid_argument(text);
  if (message[0] == 2) throw std::runtime_error(text);
  return std::vector<char>(message.begin() + 1, message.end());
}

// ---- Checkpoint -----------------------------------------------------------------------------

json sums_to_json(const SceneSums& s) {
  return json::array({s.error_sum, s.max_error, s.fragments, s.lps, s.fallbacks, s.failures, s.iterations, s.cold});
}

std::optional<SceneSums> sums_from_json(const json& j) {
  if (!j.is_array() || j.size() != 8) return std::nullopt;
  for (const json& v : j)
    if (!v.is_number()) return std::nullopt;
  SceneSums s;
  s.error_sum = j[0].get<double>();
  s.max_error = j[1].get<double>();
  s.fragments = j[2].get<std::int64_t>();
  s.lps = j[3].get<std::int64_t>();
  s.fallbacks = j[4].get<std::int64_t>();
  s.failures = j[5].get<std::int64_t>();
  s.iterations = j[6].get<std::int64_t>();
  s.cold = j[7].get<std::int64_t>();
  return s;
}

std::string checkpoint_line(const Candidate& candidate, const CandidateResult& result) {
  json j;
  j["index"] = result.index;
  j["name"] = candidate.name;
  j["singular"] = result.singular;
  j["scenes"] = json::array();
  for (const SceneSums& s : result.scenes) j["scenes"].push_back(sums_to_json(s));
  return j.dump() + "\n";
}

// The fingerprint: everything that changes a candidate's sums.
std::string run_fingerprint(const std::vector<Candidate>& candidates, const std::vector<std::uint64_t>& stacks,
                            const RunSettings& settings) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  const auto mix = [&](std::string_view s) {
    for (char c : s) hash = (hash ^ std::uint8_t(c)) * 0x100000001b3ull;
    hash = (hash ^ 0xffu) * 0x100000001b3ull;
  };
  mix("msm-evaluate-2");
  for (const Candidate& c : candidates) mix(fmt::format("{}:{}", to_string(c.technique), c.name));
  for (std::uint64_t s : stacks) mix(fmt::format("{:016x}", s));
  mix(settings.evaluate.solve_lit ? "solve-lit" : "skip-lit");
  mix(settings.evaluate.glpk_fallback ? "glpk-fallback" : "no-fallback");
  return fmt::format("{:016x}", hash);
}

class CheckpointWriter {
 public:
  explicit CheckpointWriter(const fs::path& file) : path_(file) {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec); // ranks on other machines (no shared file system)
    fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw std::runtime_error(fmt::format("{}: cannot open for appending: {}", file.string(), std::strerror(errno)));
    // A killed run may have left half a line: start on a fresh one.
    std::ifstream in(file, std::ios::binary | std::ios::ate);
    if (in && in.tellg() > 0) {
      in.seekg(-1, std::ios::end);
      char last = 0;
      in.get(last);
      if (last != '\n') write("\n");
    }
  }
  ~CheckpointWriter() {
    if (fd_ >= 0) ::close(fd_);
  }
  void write(const std::string& line) {
    const char* data = line.data();
    std::size_t left = line.size();
    while (left > 0) {
      const ssize_t written = ::write(fd_, data, left);
      if (written < 0 && errno == EINTR) continue;
      if (written <= 0)
        throw std::runtime_error(fmt::format("{}: write failed: {}", path_.string(), std::strerror(errno)));
      data += written, left -= std::size_t(written);
    }
    if (::fsync(fd_) != 0)
      throw std::runtime_error(fmt::format("{}: fsync failed: {}", path_.string(), std::strerror(errno)));
  }

 private:
  fs::path path_;
  int fd_ = -1;
};

// Rank 0: prepares DIR/checkpoint and reads what a previous run finished.
std::map<std::int64_t, CandidateResult> open_checkpoint(const fs::path& dir, const std::string& fingerprint,
                                                        const std::vector<Candidate>& candidates, std::size_t scenes,
                                                        bool fresh) {
  std::error_code ec;
  const fs::path run_file = dir / "run.json";
  if (fresh) fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw std::invalid_argument(
        fmt::format("{}: cannot create the checkpoint directory: {}", dir.string(), ec.message()));
  std::map<std::int64_t, CandidateResult> done;
  if (fs::exists(run_file)) {
    std::ifstream in(run_file);
    json j;
    try {
      in >> j;
    } catch (const json::exception&) {
      throw std::invalid_argument(
          fmt::format("{}: unreadable checkpoint description; use --fresh to start over", run_file.string()));
    }
    if (!j.contains("fingerprint") || j["fingerprint"] != fingerprint)
      throw std::invalid_argument(
          fmt::format("{}: the checkpoint belongs to a different run (other scenes, settings or "
                      "candidates); use --fresh to discard it, or another --out",
                      dir.string()));
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      if (!name.starts_with("rank") || !name.ends_with(".jsonl")) continue;
      std::ifstream lines(entry.path());
      std::string line;
      while (std::getline(lines, line)) {
        json record = json::parse(line, nullptr, false);
        if (record.is_discarded() || !record.is_object() || !record.contains("index") || !record.contains("scenes"))
          continue; // the half-written line of a killed run
        const std::int64_t index = record["index"].get<std::int64_t>();
        if (index < 0 || std::size_t(index) >= candidates.size() ||
            record.value("name", "") != candidates[index].name || !record["scenes"].is_array() ||
            record["scenes"].size() != scenes)
          throw std::invalid_argument(fmt::format("{}: a record does not match this run (candidate {}); use --fresh",
                                                  entry.path().string(), index));
        CandidateResult r;
        r.index = index;
        r.singular = record.value("singular", false);
        bool valid = true;
        for (const json& s : record["scenes"]) {
          const std::optional<SceneSums> sums = sums_from_json(s);
          valid = valid && sums.has_value();
          if (sums) r.scenes.push_back(*sums);
        }
        if (valid) done[index] = std::move(r);
      }
    }
  } else {
    json j;
    j["fingerprint"] = fingerprint;
    j["candidates"] = candidates.size();
    const std::string text = j.dump(2) + "\n";
    std::ofstream out(run_file);
    if (!(out << text) || !out.flush())
      throw std::runtime_error(fmt::format("{}: cannot write the checkpoint description", run_file.string()));
  }
  return done;
}

std::atomic<std::int64_t> g_stop_after{-1}; // run_internals.h

int default_threads(const Communicator& comm) {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  return std::max(1, int(cores) / std::max(1, comm.local_size()));
}

// The settings and the candidate list checked, and the output directory made, before any long work.
RunResult start_run(const RunSettings& settings, Communicator& comm) {
  validate(settings.stack);
  if (settings.scenes.empty()) throw std::invalid_argument("no scene to evaluate");
  if (settings.threads < 0 || settings.threads > 1024)
    throw std::invalid_argument(fmt::format("threads {} is outside [0, 1024]", settings.threads));
  RunResult run;
  run.rank = comm.rank();
  run.size = comm.size();
  try {
    run.candidates = parse_candidates(settings.candidates);
  } catch (const CandidateError& e) { throw std::invalid_argument(e.what()); }
  // Named and explicit bases are checked now (a clear error before any work); the sets of all:K and
  // sample:K:N when their turn comes (a singular one is reported in the table).
  for (const Candidate& c : run.candidates)
    if (c.technique == Technique::lp && c.listed) prepare_basis(c, settings.stack.grid); // throws SingularBasis
  run.scene_names = settings.scenes;

  on_rank0(comm, [&] {
    if (const auto problem = util::prepare_output_dir(settings.out, "msm-evaluate-probe"))
      throw std::invalid_argument(fmt::format("--out {}: {}", settings.out.string(), *problem));
    return std::vector<char>{};
  });
  return run;
}

// A scene's stack, refused when it holds nothing to evaluate.
Stack traced_stack(const std::string& name, const StackSettings& settings) {
  scene::Scene scene;
  try {
    scene = scene::load_scene(name);
  } catch (const scene::SceneError& e) { throw std::invalid_argument(e.what()); }
  Stack stack = build_stack(name, scene, settings);
  if (stack.stats.fragments == 0)
    throw std::invalid_argument(fmt::format("scene {}: the stack is empty: no surface within the light frustum", name));
  if (stack.stats.counted == 0)
    throw std::invalid_argument(fmt::format("scene {}: the stack has {} fragments but none receives light "
                                            "(every surface faces away from it): nothing to evaluate",
                                            name, stack.stats.fragments));
  return stack;
}

// The stacks: traced on rank 0, the same bits everywhere; their statistics recorded in `run`.
std::vector<Stack> shared_stacks(const RunSettings& settings, Communicator& comm, RunResult& run) {
  const auto stack_start = Clock::now();
  const std::vector<char> bytes = on_rank0(comm, [&] {
    Packer p;
    p.put(std::uint64_t(settings.scenes.size()));
    for (const std::string& name : settings.scenes) {
      const std::vector<char> s = traced_stack(name, settings.stack).serialize();
      p.put(std::uint64_t(s.size()));
      p.bytes.insert(p.bytes.end(), s.begin(), s.end());
    }
    return p.bytes;
  });
  std::vector<Stack> stacks;
  Unpacker u{bytes};
  const auto count = u.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto size = u.get<std::uint64_t>();
    if (bytes.size() - u.at < size) throw std::runtime_error("evaluate: truncated stacks from rank 0");
    stacks.push_back(Stack::deserialize(std::span<const char>(bytes.data() + u.at, std::size_t(size))));
    u.at += std::size_t(size);
  }
  for (const Stack& s : stacks) {
    run.stacks.push_back(s.stats);
    run.stack_fingerprints.push_back(s.fingerprint());
  }
  run.stack_seconds = seconds_since(stack_start);
  return stacks;
}

// The candidates of this rank: those the checkpoint has not finished, round-robin over the ranks.
// Rank 0 reads the checkpoint into `done`; every rank learns which candidates it holds.
std::vector<std::int64_t> candidates_of_rank(const RunSettings& settings, Communicator& comm,
                                             const fs::path& checkpoint_dir, std::size_t scenes, RunResult& run,
                                             std::map<std::int64_t, CandidateResult>& done) {
  const std::string fingerprint = run_fingerprint(run.candidates, run.stack_fingerprints, settings);
  const std::vector<char> bytes = on_rank0(comm, [&] {
    done = open_checkpoint(checkpoint_dir, fingerprint, run.candidates, scenes, settings.fresh);
    Packer p;
    p.put(std::uint64_t(done.size()));
    for (const auto& entry : done) p.put(entry.first);
    return p.bytes;
  });
  Unpacker u{bytes};
  const auto count = u.get<std::uint64_t>();
  std::vector<char> finished(run.candidates.size(), 0);
  for (std::uint64_t i = 0; i < count; ++i) finished[std::size_t(u.get<std::int64_t>())] = 1;
  run.resumed = std::int64_t(count);
  std::vector<std::int64_t> mine;
  std::int64_t position = 0;
  for (std::size_t i = 0; i < run.candidates.size(); ++i)
    if (!finished[i] && position++ % comm.size() == comm.rank()) mine.push_back(std::int64_t(i));
  return mine;
}

// One candidate over every stack (a singular basis: no sums, marked singular); counts its LPs.
CandidateResult evaluate_candidate(const Candidate& candidate, std::int64_t index, const std::vector<Stack>& stacks,
                                   const RunSettings& settings, std::atomic<std::int64_t>& lps) {
  CandidateResult result;
  result.index = index;
  std::optional<GridBasis> basis;
  if (candidate.technique == Technique::lp) {
    try {
      basis.emplace(prepare_basis(candidate, settings.stack.grid));
    } catch (const SingularBasis&) { result.singular = true; }
  }
  if (!result.singular)
    for (const Stack& stack : stacks) {
      result.scenes.push_back(evaluate(stack, candidate, basis ? &*basis : nullptr, settings.evaluate));
      lps += result.scenes.back().lps;
    }
  else
    result.scenes.assign(stacks.size(), SceneSums{});
  return result;
}

// This rank's candidates on a pool of threads, each result appended to the rank's checkpoint file as
// it finishes; `timing` gets the rank's counts and seconds.
std::vector<CandidateResult> compute_candidates(const std::vector<std::int64_t>& mine, const RunResult& run,
                                                const std::vector<Stack>& stacks, const RunSettings& settings,
                                                Communicator& comm, const fs::path& checkpoint_dir,
                                                const std::function<void(const Progress&)>& progress,
                                                RankTiming& timing) {
  const int threads = settings.threads > 0 ? settings.threads : default_threads(comm);
  CheckpointWriter writer(checkpoint_dir / fmt::format("rank{}.jsonl", comm.rank()));
  std::vector<CandidateResult> computed(mine.size());
  std::atomic<std::size_t> next{0};
  std::atomic<std::int64_t> finished_here{0}, lps{0};
  std::mutex mutex; // the checkpoint file, progress and the first error
  std::exception_ptr error;
  const auto compute_start = Clock::now();
  const auto worker = [&] {
    while (true) {
      const std::size_t k = next++;
      if (k >= mine.size()) return;
      {
        std::lock_guard lock(mutex);
        if (error) return;
      }
      try {
        const Candidate& candidate = run.candidates[std::size_t(mine[k])];
        computed[k] = evaluate_candidate(candidate, mine[k], stacks, settings, lps);
        std::lock_guard lock(mutex);
        writer.write(checkpoint_line(candidate, computed[k]));
        const std::int64_t count = ++finished_here;
        if (const std::int64_t stop = g_stop_after; stop >= 0 && count >= stop) std::_Exit(3);
        if (progress && comm.rank() == 0) progress({count, std::int64_t(mine.size()), seconds_since(compute_start)});
      } catch (const std::exception& e) {
        // Not an invalid_argument: an error of this rank alone (callers abort the other ranks).
        std::lock_guard lock(mutex);
        if (!error) error = std::make_exception_ptr(std::runtime_error(e.what()));
        return;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::min<int>(threads, std::max<int>(1, int(mine.size()))); ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  if (progress && comm.rank() == 0 && mine.empty()) progress({0, 0, 0.0});

  timing.rank = comm.rank();
  timing.threads = threads;
  timing.candidates = std::int64_t(mine.size());
  timing.lps = lps;
  timing.seconds = seconds_since(compute_start);
  return computed;
}

// Every rank's results and timing gathered at rank 0, into `run` with the checkpoint's (`done`): one
// result per candidate, by index.
void gather_results(const std::vector<CandidateResult>& computed, const RankTiming& timing, std::size_t scenes,
                    Communicator& comm, std::map<std::int64_t, CandidateResult>& done, RunResult& run) {
  Packer p;
  p.put(timing.rank), p.put(timing.threads), p.put(timing.candidates), p.put(timing.lps), p.put(timing.seconds);
  p.put(std::uint64_t(computed.size()));
  for (const CandidateResult& r : computed) {
    p.put(r.index), p.put(std::int64_t(r.singular ? 1 : 0));
    for (const SceneSums& s : r.scenes) put_sums(p, s);
  }
  const std::vector<std::vector<char>> all =
      comm.size() > 1 ? comm.gather(p.bytes) : std::vector<std::vector<char>>{p.bytes};
  if (comm.rank() != 0) return;
  std::vector<std::optional<CandidateResult>> table(run.candidates.size());
  for (auto& [index, r] : done) table[std::size_t(index)] = std::move(r);
  for (const std::vector<char>& bytes : all) {
    Unpacker u{bytes};
    RankTiming t;
    t.rank = u.get<int>();
    t.threads = u.get<int>();
    t.candidates = u.get<std::int64_t>();
    t.lps = u.get<std::int64_t>();
    t.seconds = u.get<double>();
    run.ranks.push_back(t);
    const auto count = u.get<std::uint64_t>();
    for (std::uint64_t i = 0; i < count; ++i) {
      CandidateResult r;
      r.index = u.get<std::int64_t>();
      r.singular = u.get<std::int64_t>() != 0;
      for (std::size_t s = 0; s < scenes; ++s) r.scenes.push_back(get_sums(u));
      table.at(std::size_t(r.index)) = std::move(r);
    }
  }
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (!table[i]) throw std::runtime_error(fmt::format("evaluate: no result for candidate {}", i));
    run.results.push_back(std::move(*table[i]));
  }
}

} // namespace

void set_stop_after(std::int64_t candidates) { g_stop_after = candidates; }

RunResult run_evaluation(const RunSettings& settings, Communicator& comm,
                         const std::function<void(const Progress&)>& progress) {
  const auto start = Clock::now();
  RunResult run = start_run(settings, comm);
  const std::vector<Stack> stacks = shared_stacks(settings, comm, run);
  const fs::path checkpoint_dir = settings.out / "checkpoint";
  std::map<std::int64_t, CandidateResult> done; // rank 0: what the checkpoint holds
  const std::vector<std::int64_t> mine = candidates_of_rank(settings, comm, checkpoint_dir, stacks.size(), run, done);
  RankTiming timing;
  const std::vector<CandidateResult> computed =
      compute_candidates(mine, run, stacks, settings, comm, checkpoint_dir, progress, timing);
  gather_results(computed, timing, stacks.size(), comm, done, run);
  run.total_seconds = seconds_since(start);
  return run;
}

namespace {

class SingleProcess final : public Communicator {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  int local_size() const override { return 1; }
  void broadcast(std::vector<char>&) override {}
  std::vector<std::vector<char>> gather(const std::vector<char>& bytes) override { return {bytes}; }
  void barrier() override {}
};

std::unique_ptr<Communicator> make_single() { return std::make_unique<SingleProcess>(); }

} // namespace

std::unique_ptr<Communicator> single_process() { return make_single(); }

} // namespace msm::evaluate
