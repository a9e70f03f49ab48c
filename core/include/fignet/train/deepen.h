// Growing a trained network deeper. Message-passing steps added to a run's model start as the
// identity: every MLP of a new step has its LayerNorm's scale and offset at zero, so it outputs
// zero and each latent passes through the step's residual unchanged. The deeper network predicts
// exactly what the trained one did, and training goes on from there with more capacity, without
// starting again from scratch. With scales at exactly zero the new steps' other weights get no
// gradient until the scales move, and under Adam the scales wander about zero with the noise of
// the batches (measured: |scale| ~0.001 after 3,600 steps at 1e-4), so a small positive starting
// scale may be given instead: the new steps then add that fraction of a normalised update, a
// near-identity, and their weights learn in a consistent direction from the first step.
#pragma once

#include <memory>
#include <vector>

#include "fignet/model/model.h"
#include "fignet/train/trainer.h"

namespace fignet {

// Where each step of a deepened processor comes from: the index of the trained step it copies,
// or -1 for a new step. The `added` new steps are spread evenly among the `trained` ones, each
// after a trained step (with added == trained: trained, new, trained, new, ...).
// Throws ConfigError unless trained >= 1 and added >= 1.
std::vector<int> deepened_step_sources(int trained, int added);

struct DeepenedRun {
  std::shared_ptr<const Model> model;
  // The optimizer's moments and the parameters' average carried to the trained tensors; zero
  // moments and the initial values for the new ones. The step count is kept, so the learning
  // rate's schedule goes on where it was.
  TrainerState state;
};

// `model` with `added_steps` new steps (deepened_step_sources), and `state`, the run's training
// state (its moments and average may be empty: a model without a run), carried over. New steps'
// LayerNorm scales start at `new_step_scale` (0: the identity) and offsets at zero; their other
// weights are drawn as a new model's would be, from the model's seed. Throws ConfigError when
// added_steps < 1, new_step_scale is outside [0, 1], the config would become invalid, or the state
// does not fit the model.
DeepenedRun deepen(const Model& model, const TrainerState& state, int added_steps,
                   float new_step_scale = 0.0f);

}  // namespace fignet
