// The communication data-parallel training needs, as an interface: core stays free of MPI, and
// one process is the default (fignet/parallel/mpi_collective.h implements it with MPI).
#pragma once

#include <span>
#include <vector>

namespace fignet {

class Collective {
 public:
  virtual ~Collective() = default;
  virtual int rank() const { return 0; }
  virtual int size() const { return 1; }
  // In-place element-wise sums over every process (each call one collective operation).
  virtual void sum(std::span<float> values) { (void)values; }
  virtual void sum(std::span<double> values) { (void)values; }
  // Every process's `values` concatenated on process 0 in process order (empty elsewhere).
  virtual std::vector<double> gather(const std::vector<double>& values) { return values; }
  // Seconds spent inside the sums so far (communication and waiting for other processes).
  virtual double seconds_communicating() const { return 0.0; }
};

}  // namespace fignet
