// Training FIGNet on trajectories: batches of noisy samples concatenated into one graph, forward,
// MSE in normalised target space over dynamic nodes, backward, Adam. Deterministic for a given
// seed and thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "fignet/graph/graph_builder.h"
#include "fignet/model/model.h"
#include "fignet/nn/adam.h"
#include "fignet/train/training_batch.h"

namespace fignet {

struct TrainerConfig {
  int batch_size = 4;  // scenes per step, concatenated into one graph
  AdamConfig adam;     // learning rate 1e-3 → 1e-4 over adam.decay_steps
  std::uint64_t seed = 1;
};

// Everything besides the model that makes training continue exactly where it stopped: the
// optimizer's moments and step count and the sampling/noise generator's state.
struct TrainerState {
  std::int64_t step = 0;
  std::vector<float> first_moment, second_moment;
  std::string rng;  // std::mt19937_64 in its standard text form
};

struct TrainStep {
  std::int64_t step = 0;  // steps done, this one included
  double loss = 0.0;      // mean squared normalised error over the batch's dynamic nodes
  float learning_rate = 0.0f;
};

class Trainer {
 public:
  // Trains a fresh model of `config` (or continues `initial`) on `data`, which must outlive it.
  Trainer(const ModelConfig& config, const TrainerConfig& trainer_config,
          const std::vector<Trajectory>& data, const Model* initial = nullptr);

  // One optimisation step on a random batch.
  TrainStep step();
  // Runs `steps` steps; `on_step` sees each result and may stop early by returning false.
  void run(std::int64_t steps, const std::function<bool(const TrainStep&)>& on_step);
  // The loss of one batch without updating anything (noise included, as in training).
  double evaluate_loss(const std::vector<SampleRef>& samples);

  // An immutable snapshot of the current parameters and statistics.
  std::shared_ptr<const Model> model() const;
  std::int64_t steps_done() const { return adam_.step(); }
  const std::vector<SampleRef>& samples() const { return samples_; }

  // Checkpoints: state() with model() captures training; restore() continues it exactly.
  TrainerState state() const;
  // Throws ConfigError when the state does not fit this trainer's parameter count.
  void restore(const TrainerState& state);
  const TrainerConfig& trainer_config() const { return trainer_config_; }

  // State for data-parallel training.
  std::vector<float>& parameters() { return params_; }
  Adam& optimizer() { return adam_; }
  Normalizers& normalizers() { return normalizers_; }
  std::mt19937_64& rng() { return rng_; }

 private:
  // Builds the batch graph and targets; accumulates statistics while they are not frozen.
  void prepare_batch(const std::vector<SampleRef>& batch, bool accumulate);
  double loss_and_gradient(bool with_gradient);

  ModelConfig config_;
  TrainerConfig trainer_config_;
  const std::vector<Trajectory>& data_;
  Network network_;
  std::vector<float> params_;
  AlignedFloats grads_;  // aligned: reductions into it then sum in an address-independent order
  Normalizers normalizers_;
  Adam adam_;
  std::mt19937_64 rng_;
  std::vector<SampleRef> samples_, batch_;
  // Scratch reused every step.
  GraphBuilder builder_;
  Graph graph_;
  std::vector<Scene> scenes_;
  std::vector<Points> scene_targets_;
  RowMatrixXf targets_, normalized_targets_, d_output_;
  std::vector<std::uint8_t> in_loss_;
  NetworkWorkspace workspace_;
};

}  // namespace fignet
