#include "fignet/train/trainer.h"

#include <fmt/format.h>

#include <algorithm>
#include <sstream>

#include "fignet/error.h"

namespace fignet {

Trainer::Trainer(const ModelConfig& config, const TrainerConfig& trainer_config,
                 const std::vector<Trajectory>& data, const Model* initial)
    : config_(config),
      trainer_config_(trainer_config),
      data_(data),
      network_(config),
      normalizers_(network_.make_normalizers()),
      rng_(trainer_config.seed),
      builder_(config.graph) {
  if (trainer_config.batch_size < 1) {
    throw ConfigError(
        fmt::format("trainer: batch_size = {} (must be >= 1)", trainer_config.batch_size));
  }
  for (const Trajectory& trajectory : data_) trajectory.validate();
  samples_ = enumerate_samples(data_, config.graph.history);
  if (samples_.empty()) {
    throw ConfigError(
        fmt::format("trainer: no training samples: every trajectory needs more than "
                    "history + 1 = {} frames",
                    config.graph.history + 1));
  }
  if (initial) {
    params_ = initial->parameters();
    normalizers_ = initial->normalizers();
  } else {
    network_.layout().initialize(params_, config.seed);
  }
  grads_.assign(params_.size(), 0.0f);
  adam_ = Adam(params_.size(), trainer_config.adam);
}

void Trainer::prepare_batch(const std::vector<SampleRef>& batch, bool accumulate) {
  const int h = config_.graph.history;
  scenes_.resize(batch.size());
  scene_targets_.resize(batch.size());
  for (size_t b = 0; b < batch.size(); ++b) {
    make_noisy_sample(data_[batch[b].trajectory], batch[b].frame, h, config_.noise_std, rng_,
                      scenes_[b], scene_targets_[b]);
  }
  builder_.build(scenes_, graph_);
  gather_targets(graph_, scene_targets_, targets_, in_loss_);
  if (!accumulate) return;
  // Statistics of every input block and of the dynamic nodes' targets (MeshGraphNets style).
  network_.accumulate_input_statistics(graph_, normalizers_);
  RowMatrixXf dynamic_targets(std::count(in_loss_.begin(), in_loss_.end(), 1), 3);
  for (Eigen::Index i = 0, r = 0; i < targets_.rows(); ++i) {
    if (in_loss_[i]) dynamic_targets.row(r++) = targets_.row(i);
  }
  normalizers_.target.accumulate(dynamic_targets);
}

double Trainer::loss_and_gradient(bool with_gradient) {
  const ConstMatrixView output =
      network_.forward(params_.data(), normalizers_, graph_, workspace_, with_gradient);
  normalized_targets_.resize(targets_.rows(), 3);
  normalizers_.target.normalize(targets_, normalized_targets_);
  const auto count = std::count(in_loss_.begin(), in_loss_.end(), 1);
  if (count == 0) return 0.0;
  d_output_.setZero(output.rows(), 3);
  double loss = 0.0;
  const float scale = 2.0f / static_cast<float>(3 * count);
  for (Eigen::Index i = 0; i < output.rows(); ++i) {
    if (!in_loss_[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const float error = output(i, c) - normalized_targets_(i, c);
      loss += static_cast<double>(error) * error;
      d_output_(i, c) = scale * error;
    }
  }
  loss /= static_cast<double>(3 * count);
  if (with_gradient) {
    std::fill(grads_.begin(), grads_.end(), 0.0f);
    network_.backward(params_.data(), grads_.data(), graph_, d_output_, workspace_);
  }
  return loss;
}

TrainStep Trainer::step() {
  std::uniform_int_distribution<size_t> pick(0, samples_.size() - 1);
  batch_.resize(trainer_config_.batch_size);
  for (SampleRef& sample : batch_) sample = samples_[pick(rng_)];
  prepare_batch(batch_, /*accumulate=*/true);
  TrainStep result;
  result.learning_rate = adam_.learning_rate();
  result.loss = loss_and_gradient(true);
  adam_.update(params_, grads_);
  result.step = adam_.step();
  return result;
}

void Trainer::run(std::int64_t steps, const std::function<bool(const TrainStep&)>& on_step) {
  for (std::int64_t i = 0; i < steps; ++i) {
    const TrainStep result = step();
    if (on_step && !on_step(result)) return;
  }
}

double Trainer::evaluate_loss(const std::vector<SampleRef>& samples) {
  prepare_batch(samples, /*accumulate=*/false);
  return loss_and_gradient(false);
}

TrainerState Trainer::state() const {
  std::ostringstream rng;
  rng << rng_;
  return {adam_.step(), adam_.first_moment(), adam_.second_moment(), rng.str()};
}

void Trainer::restore(const TrainerState& state) {
  if (state.first_moment.size() != params_.size() || state.second_moment.size() != params_.size()) {
    throw ConfigError(fmt::format("trainer: optimizer state has {} and {} entries, the model {}",
                                  state.first_moment.size(), state.second_moment.size(),
                                  params_.size()));
  }
  std::istringstream rng(state.rng);
  rng >> rng_;
  if (!rng) throw ConfigError("trainer: the random generator state cannot be parsed");
  adam_.first_moment() = state.first_moment;
  adam_.second_moment() = state.second_moment;
  adam_.set_step(state.step);
}

std::shared_ptr<const Model> Trainer::model() const {
  return std::make_shared<const Model>(config_, params_, normalizers_);
}

}  // namespace fignet
