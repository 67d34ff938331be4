// MPI ranks (mpi.h). Compiled with MSM_HAVE_MPI when CMake found MPI; without it, the end of the
// file says so: mpi_supported() is false, mpi_world() refuses with the reason, and there are no
// other ranks to abort.
#include "msm/evaluate/mpi.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

#if MSM_HAVE_MPI
#include <mpi.h>
#endif

namespace msm::evaluate {

bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

#if MSM_HAVE_MPI

namespace {

void check(int code, const char* what) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(std::string("MPI: ") + what + " failed: " + std::string(text, std::size_t(length)));
}

class MpiWorld final : public Communicator {
 public:
  MpiWorld() {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
      int provided = 0;
      check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
      owner_ = true;
    }
    // Errors come back as codes (and become exceptions) instead of aborting inside MPI.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    check(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
    check(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
    MPI_Comm node;
    check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node),
          "MPI_Comm_split_type");
    MPI_Comm_size(node, &local_size_);
    MPI_Comm_free(&node);
  }
  ~MpiWorld() override {
    if (owner_) MPI_Finalize();
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  int local_size() const override { return local_size_; }

  void broadcast(std::vector<char>& bytes) override {
    unsigned long long count = bytes.size();
    check(MPI_Bcast(&count, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD), "MPI_Bcast");
    bytes.resize(count);
    // In pieces below 2^31 bytes (MPI counts are int).
    for (unsigned long long at = 0; at < count;) {
      const int piece = int(std::min<unsigned long long>(count - at, 1ull << 30));
      check(MPI_Bcast(bytes.data() + at, piece, MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
      at += unsigned(piece);
    }
  }

  std::vector<std::vector<char>> gather(const std::vector<char>& bytes) override {
    // Point to point, one rank after the other: no int displacements to overflow.
    std::vector<std::vector<char>> all;
    if (rank_ != 0) {
      unsigned long long count = bytes.size();
      check(MPI_Send(&count, 1, MPI_UNSIGNED_LONG_LONG, 0, 1, MPI_COMM_WORLD), "MPI_Send");
      for (unsigned long long at = 0; at < count;) {
        const int piece = int(std::min<unsigned long long>(count - at, 1ull << 30));
        check(MPI_Send(bytes.data() + at, piece, MPI_CHAR, 0, 2, MPI_COMM_WORLD), "MPI_Send");
        at += unsigned(piece);
      }
      return all;
    }
    all.push_back(bytes);
    for (int source = 1; source < size_; ++source) {
      unsigned long long count = 0;
      check(MPI_Recv(&count, 1, MPI_UNSIGNED_LONG_LONG, source, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
      std::vector<char> received(count);
      for (unsigned long long at = 0; at < count;) {
        const int piece = int(std::min<unsigned long long>(count - at, 1ull << 30));
        check(MPI_Recv(received.data() + at, piece, MPI_CHAR, source, 2, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
              "MPI_Recv");
        at += unsigned(piece);
      }
      all.push_back(std::move(received));
    }
    return all;
  }

  void barrier() override { check(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier"); }

 private:
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool owner_ = false;
};

} // namespace

bool mpi_supported() { return true; }

std::unique_ptr<Communicator> mpi_world() { return std::make_unique<MpiWorld>(); }

void mpi_abort(int status) {
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  if (initialized && !finalized) MPI_Abort(MPI_COMM_WORLD, status);
}

#else

bool mpi_supported() { return false; }

std::unique_ptr<Communicator> mpi_world() {
  throw std::runtime_error("this build of msm has no MPI support (Open MPI was not found at configure time)");
}

void mpi_abort(int) {}

#endif

} // namespace msm::evaluate
