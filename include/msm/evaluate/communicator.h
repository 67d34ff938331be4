// How the ranks of a distributed evaluation talk: one process (threads only), or MPI ranks
// (msm/evaluate/mpi.h). run_evaluation (run.h) needs only these collective operations.
#pragma once

#include <memory>
#include <vector>

namespace msm::evaluate {

class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0; // 0 .. size() - 1; rank 0 reads inputs and writes outputs
  virtual int size() const = 0;
  virtual int local_size() const = 0; // ranks on this machine (they share its cores)
  // Rank 0's bytes replace every other rank's (collective).
  virtual void broadcast(std::vector<char>& bytes) = 0;
  // Every rank's bytes, by rank, at rank 0 (empty elsewhere) (collective).
  virtual std::vector<std::vector<char>> gather(const std::vector<char>& bytes) = 0;
  virtual void barrier() = 0;
};

// The communicator of a process that runs alone: rank 0 of 1.
std::unique_ptr<Communicator> single_process();

} // namespace msm::evaluate
