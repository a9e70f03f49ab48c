// Thread counts for one scope, restored when it ends (also when a test's assertion returns early
// or the code under test throws), for tests that compare results across thread counts.
#pragma once

#include <omp.h>

#include <Eigen/Core>

namespace fignet::testing {

class ScopedThreads {
 public:
  explicit ScopedThreads(int threads) : previous_(omp_get_max_threads()) {
    omp_set_num_threads(threads);
  }
  ~ScopedThreads() { omp_set_num_threads(previous_); }
  ScopedThreads(const ScopedThreads&) = delete;
  ScopedThreads& operator=(const ScopedThreads&) = delete;

 private:
  int previous_;
};

// Eigen::nbThreads() for one scope (the threads gemm() shares a product's blocks among), back to
// Eigen's default when it ends: 0, i.e. OpenMP's count.
class ScopedEigenThreads {
 public:
  explicit ScopedEigenThreads(int threads) { Eigen::setNbThreads(threads); }
  ~ScopedEigenThreads() { Eigen::setNbThreads(0); }
  ScopedEigenThreads(const ScopedEigenThreads&) = delete;
  ScopedEigenThreads& operator=(const ScopedEigenThreads&) = delete;
};

}  // namespace fignet::testing
