// Work on each of n trajectories shared among threads, each thread with a predictor of its own
// (predictors hold per-step scratch and are not shared); the first failure is rethrown.
#pragma once

#include <algorithm>
#include <exception>
#include <functional>
#include <memory>

#include "fignet/rollout/predictor.h"

namespace fignet::detail {

template <class Work>  // void(AccelerationPredictor&, int trajectory)
void for_each_trajectory(
    const std::function<std::unique_ptr<AccelerationPredictor>()>& make_predictor, int n,
    int threads, Work&& work) {
  std::exception_ptr failure;
#pragma omp parallel num_threads(std::max(1, std::min(threads, n)))
  {
    std::unique_ptr<AccelerationPredictor> predictor;
#pragma omp for schedule(dynamic, 1)
    for (int i = 0; i < n; ++i) {
      try {
        if (!predictor) predictor = make_predictor();
        work(*predictor, i);
      } catch (...) {
#pragma omp critical
        if (!failure) failure = std::current_exception();
      }
    }
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace fignet::detail
