// Adam over a flat parameter array, with the seed's exponential learning-rate decay
// (1e-3 to 1e-4 over the configured number of steps, then held). The decay may start at a later
// step: a continuation of a finished run restarts from a higher rate that way.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace fignet {

struct AdamConfig {
  float learning_rate_start = 1e-3f;
  float learning_rate_end = 1e-4f;
  std::int64_t decay_steps = 1'000'000;
  // The step the decay starts from: the start rate up to it, the end rate from it + decay_steps.
  std::int64_t decay_start_step = 0;
  float beta1 = 0.9f, beta2 = 0.999f, epsilon = 1e-8f;
};

class Adam {
 public:
  Adam() = default;
  Adam(size_t num_parameters, const AdamConfig& config);

  // One update of `params` from `grads`, on the OpenMP threads in blocks of kParallelBlock
  // parameters (the same bits for any thread count); increments step().
  // Throws ConfigError when either size differs from the optimizer's.
  static constexpr size_t kParallelBlock = 16384;
  void update(std::span<float> params, std::span<const float> grads);
  float learning_rate() const;  // the rate the next update() will use
  std::int64_t step() const { return step_; }
  const AdamConfig& config() const { return config_; }

  // State for checkpoints: the first and second moments and the step count.
  std::vector<float>& first_moment() { return m_; }
  std::vector<float>& second_moment() { return v_; }
  const std::vector<float>& first_moment() const { return m_; }
  const std::vector<float>& second_moment() const { return v_; }
  void set_step(std::int64_t step) { step_ = step; }

 private:
  AdamConfig config_;
  std::vector<float> m_, v_;
  std::int64_t step_ = 0;
};

}  // namespace fignet
