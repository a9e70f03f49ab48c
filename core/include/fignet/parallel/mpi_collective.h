// MPI for data-parallel training and evaluation: the processes of MPI_COMM_WORLD as a Collective
// (one MPI_Allreduce per sum), and the session that initialises and finalises MPI only when the
// program was started by a launcher (mpirun, srun), so a plain run never touches MPI.
#pragma once

#include <vector>

#include "fignet/train/collective.h"

namespace fignet {

class MpiSession {
 public:
  // Initialises MPI when a launcher's environment is present (OpenMPI, PMIx, PMI, Slurm).
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  bool active() const { return active_; }
  // Ends every process (after an error on one, the others would wait forever).
  [[noreturn]] void abort(int code) const;

 private:
  bool active_ = false;
};

class MpiCollective : public Collective {
 public:
  MpiCollective();  // MPI_COMM_WORLD; MPI must be initialised
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void sum(std::span<float> values) override;
  void sum(std::span<double> values) override;
  double seconds_communicating() const override { return seconds_; }
  std::vector<double> gather(const std::vector<double>& values) override;

 private:
  int rank_ = 0, size_ = 1;
  double seconds_ = 0.0;
};

}  // namespace fignet
