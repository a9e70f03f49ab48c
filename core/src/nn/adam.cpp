#include "fignet/nn/adam.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <omp.h>

#include "fignet/error.h"
#include "parallel/parallel_for.h"

namespace fignet {

Adam::Adam(size_t num_parameters, const AdamConfig& config)
    : config_(config), m_(num_parameters, 0.0f), v_(num_parameters, 0.0f) {}

float Adam::learning_rate() const {
  const double progress =
      std::clamp(static_cast<double>(step_ - config_.decay_start_step) /
                     static_cast<double>(std::max<std::int64_t>(1, config_.decay_steps)),
                 0.0, 1.0);
  return static_cast<float>(
      config_.learning_rate_start *
      std::pow(config_.learning_rate_end / config_.learning_rate_start, progress));
}

void Adam::update(std::span<float> params, std::span<const float> grads) {
  if (params.size() != m_.size() || grads.size() != m_.size()) {
    throw ConfigError(fmt::format("adam: {} parameters and {} gradients for an optimizer of {}",
                                  params.size(), grads.size(), m_.size()));
  }
  const float rate = learning_rate();
  ++step_;
  const float correction1 = 1.0f - std::pow(config_.beta1, static_cast<float>(step_));
  const float correction2 = 1.0f - std::pow(config_.beta2, static_cast<float>(step_));
  const float step_size = rate / correction1;
  const float inv_sqrt_correction2 = 1.0f / std::sqrt(correction2);
  // Fixed blocks shared among the threads: each block runs the same code whatever the thread
  // count, so the parameters do not depend on it. Threads pay where a step is short (a GPU's at
  // batch 8 spent as long in this loop, on one thread, as in the network).
  float* p = params.data();
  float* m = m_.data();
  float* v = v_.data();
  const float* g = grads.data();
  const float beta1 = config_.beta1, beta2 = config_.beta2, epsilon = config_.epsilon;
  detail::parallel_for_blocks(
      params.size(), kParallelBlock, omp_get_max_threads(),
      // By value: the loop then reads no pointer through memory and vectorises.
      [=](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
          m[i] = beta1 * m[i] + (1.0f - beta1) * g[i];
          v[i] = beta2 * v[i] + (1.0f - beta2) * g[i] * g[i];
          p[i] -= step_size * m[i] / (std::sqrt(v[i]) * inv_sqrt_correction2 + epsilon);
        }
      });
}

}  // namespace fignet
