// Growing a trained network, deeper or wider, so that training goes on with more capacity without
// starting again from scratch; the grown network first predicts exactly what the trained one did.
//
// Deeper: every MLP of a new message-passing step has its LayerNorm's scale and offset at zero,
// so it outputs zero and each latent passes through the step's residual unchanged. With scales at
// exactly zero the new steps' other weights get no gradient until the scales move, and under Adam
// the scales wander about zero with the noise of the batches (measured: |scale| ~0.001 after
// 3,600 steps at 1e-4), so a small positive starting scale may be given instead: the new steps
// then add that fraction of a normalised update, a near-identity, and their weights learn in a
// consistent direction from the first step.
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

struct GrownRun {
  std::shared_ptr<const Model> model;
  // The optimizer's moments and the parameters' average carried to the trained weights; zero
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
GrownRun deepen(const Model& model, const TrainerState& state, int added_steps,
                float new_step_scale = 0.0f);

// Wider: the MLPs' hidden layers (ModelConfig::hidden_size, object_hidden_size) grown to
// `hidden_size` and the object-node MLPs' to `object_hidden_size` (0: leave that field as it is).
// A new hidden unit's incoming weights are drawn as a new model's, its outgoing weights are zero:
// it changes no output until training moves them, and they get a gradient from the first step
// (the unit's activation times the output's gradient), unlike a new step at scale zero.
// Throws ConfigError when a width would shrink, nothing would grow, the config would become
// invalid, or the state does not fit the model.
GrownRun widen(const Model& model, const TrainerState& state, int hidden_size,
               int object_hidden_size);

}  // namespace fignet
