#include "fignet/nn/adam.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "fignet/error.h"

namespace fignet {

Adam::Adam(size_t num_parameters, const AdamConfig& config)
    : config_(config), m_(num_parameters, 0.0f), v_(num_parameters, 0.0f) {}

float Adam::learning_rate() const {
  const double progress =
      std::min(1.0, static_cast<double>(step_) / std::max<std::int64_t>(1, config_.decay_steps));
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
  for (size_t i = 0; i < params.size(); ++i) {
    m_[i] = config_.beta1 * m_[i] + (1.0f - config_.beta1) * grads[i];
    v_[i] = config_.beta2 * v_[i] + (1.0f - config_.beta2) * grads[i] * grads[i];
    params[i] -= step_size * m_[i] / (std::sqrt(v_[i]) * inv_sqrt_correction2 + config_.epsilon);
  }
}

}  // namespace fignet
