// OpenMP's thread count for one scope, restored when it ends (also when a test's assertion
// returns early), for tests that compare results across thread counts.
#pragma once

#include <omp.h>

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

}  // namespace fignet::testing
