// Work on each of n trajectories shared among threads, each thread with a predictor of its own
// (predictors hold per-step scratch and are not shared); the first failure is rethrown.
#pragma once

#include <algorithm>
#include <functional>
#include <memory>
#include <vector>

#include "fignet/rollout/predictor.h"
#include "parallel/parallel_for.h"

namespace fignet::detail {

template <class Work>  // void(AccelerationPredictor&, int trajectory)
void for_each_trajectory(
    const std::function<std::unique_ptr<AccelerationPredictor>()>& make_predictor, int n,
    int threads, Work&& work) {
  const int team = std::max(1, std::min(threads, n));
  std::vector<std::unique_ptr<AccelerationPredictor>> predictors(team);
  parallel_for(n, team, Schedule::kOneAtATime, [&](int i, int thread) {
    std::unique_ptr<AccelerationPredictor>& predictor = predictors[thread];
    if (!predictor) predictor = make_predictor();
    work(*predictor, i);
  });
}

}  // namespace fignet::detail
