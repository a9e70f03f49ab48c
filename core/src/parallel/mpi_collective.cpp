#include "fignet/parallel/mpi_collective.h"

#include <mpi.h>

#include <chrono>
#include <cstdlib>

#include "fignet/error.h"

namespace fignet {

namespace {

bool started_by_a_launcher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_PROCID"}) {
    if (std::getenv(name)) return true;
  }
  return false;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
  if (!started_by_a_launcher()) return;
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised && MPI_Init(argc, argv) != MPI_SUCCESS) {
    throw ConfigError("MPI_Init failed: is this mpirun's environment?");
  }
  active_ = true;
}

MpiSession::~MpiSession() {
  if (active_) MPI_Finalize();
}

void MpiSession::abort(int code) const {
  if (active_) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

MpiCollective::MpiCollective() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) throw ConfigError("MpiCollective: MPI is not initialised");
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

void MpiCollective::sum(std::span<float> values) {
  const auto start = std::chrono::steady_clock::now();
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_FLOAT, MPI_SUM,
                MPI_COMM_WORLD);
  seconds_ += seconds_since(start);
}

void MpiCollective::sum(std::span<double> values) {
  const auto start = std::chrono::steady_clock::now();
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM,
                MPI_COMM_WORLD);
  seconds_ += seconds_since(start);
}

std::vector<double> MpiCollective::gather(const std::vector<double>& values) {
  const int count = static_cast<int>(values.size());
  std::vector<int> counts(static_cast<size_t>(size_)), offsets(static_cast<size_t>(size_));
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::vector<double> all;
  if (rank_ == 0) {
    int total = 0;
    for (int r = 0; r < size_; ++r) {
      offsets[static_cast<size_t>(r)] = total;
      total += counts[static_cast<size_t>(r)];
    }
    all.resize(static_cast<size_t>(total));
  }
  MPI_Gatherv(values.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
              MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return all;
}

}  // namespace fignet
