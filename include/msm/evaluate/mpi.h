// MPI ranks for msm::evaluate (Open MPI from Debian, or any MPI-3 library), in the separate target
// msm::evaluate_mpi so that the evaluation library itself needs no MPI.
//
// The `msm` binary runs with and without mpirun: launched_by_mpi() looks at the environment that
// MPI launchers give their ranks (Open MPI: OMPI_COMM_WORLD_SIZE; PMIx: PMIX_RANK; MPICH/Hydra and
// Slurm's PMI: PMI_RANK, PMI_SIZE) before anything initializes MPI, and only then is MPI_Init
// called. Without those variables the process runs alone (single_process()) and never touches MPI,
// so no MPI runtime (and no singleton MPI_Init, which some installations refuse or stall on) is
// needed.
#pragma once

#include <memory>

#include "msm/evaluate/communicator.h"

namespace msm::evaluate {

// True when this build can use MPI.
bool mpi_supported();
// True when an MPI launcher started this process (environment variables above).
bool launched_by_mpi();

// MPI_Init_thread (funneled: only the calling thread talks MPI) on first use, MPI_Finalize when the
// communicator is destroyed. Throws std::runtime_error without MPI support or when MPI fails.
std::unique_ptr<Communicator> mpi_world();
// Ends every rank of the job with this exit status (MPI_Abort); used when one rank fails so that the
// others do not wait forever in a collective. Does nothing without MPI or outside mpirun.
void mpi_abort(int status);

} // namespace msm::evaluate
