// Central finite differences against hand-written backward passes, in float32.
//
// Per tensor, up to `per_tensor` random entries are compared as one vector: the tensor passes when
// ‖analytic − numeric‖ <= 5 % of ‖numeric‖ + a noise floor of 2e-3 per entry. Entry-by-entry
// comparison cannot resolve small gradients: float32 forward rounding over hundreds of outputs
// puts ~1e-2 of noise on each numeric derivative, which averages out over a vector, while a wrong
// backward path gives an O(1) relative error.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "fignet/nn/parameters.h"

namespace fignet::testing {

// `loss(params)` evaluates the scalar loss (sum it in double); `analytic` holds its gradient.
// Returns the number of tensors that failed, each reported with its error.
inline int check_gradients(const ParameterLayout& layout, std::vector<float> params,
                           const std::vector<float>& analytic,
                           const std::function<double(const std::vector<float>&)>& loss,
                           int per_tensor, float step = 1e-3f) {
  std::mt19937 rng(99);
  int failed = 0;
  for (const TensorInfo& t : layout.tensors()) {
    std::vector<size_t> entries(t.size());
    for (size_t i = 0; i < entries.size(); ++i) entries[i] = t.offset + i;
    std::shuffle(entries.begin(), entries.end(), rng);
    entries.resize(std::min<size_t>(entries.size(), per_tensor));
    double diff2 = 0.0, numeric2 = 0.0;
    for (size_t i : entries) {
      const float saved = params[i];
      params[i] = saved + step;
      const double up = loss(params);
      params[i] = saved - step;
      const double down = loss(params);
      params[i] = saved;
      const double numeric = (up - down) / (2.0 * step);
      diff2 += (analytic[i] - numeric) * (analytic[i] - numeric);
      numeric2 += numeric * numeric;
    }
    const double floor = 2e-3 * std::sqrt(static_cast<double>(entries.size()));
    if (std::sqrt(diff2) > 0.05 * std::sqrt(numeric2) + floor) {
      ++failed;
      ADD_FAILURE() << t.name << ": |analytic - numeric| = " << std::sqrt(diff2)
                    << ", |numeric| = " << std::sqrt(numeric2) << " over " << entries.size()
                    << " entries";
    }
  }
  return failed;
}

}  // namespace fignet::testing
