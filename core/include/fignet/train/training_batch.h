// One training batch: scenes at random frames of the training trajectories, random-walk noise on
// their input histories (GNS), and the noise-corrected target accelerations of their nodes.
#pragma once

#include <random>
#include <span>
#include <vector>

#include "fignet/data/trajectory.h"
#include "fignet/graph/graph.h"
#include "fignet/model/config.h"

namespace fignet {

struct SampleRef {
  int trajectory = 0, frame = 0;  // predict frame + 1 from frames frame − h … frame
};

// Every (trajectory, frame) that has h past frames and a next frame.
std::vector<SampleRef> enumerate_samples(const std::vector<Trajectory>& data, int history);

// Fills `scene` for the sample and adds random-walk noise to the positions of its dynamic nodes:
// per-step velocity noise of std noise_std/sqrt(h), summed over the history, so the current
// position's noise has std noise_std and the oldest none. Writes each node's target
// x^{t+1} − 2x̃^t + x̃^{t−1} + (1 − c)·n^t with c = position_correction: c = 0 asks the model to
// undo the velocity noise only (GNS, the paper), c = 1 to return the node to its clean next
// position, undoing the position noise too (rows follow scene.objects; kinematic rows are zero).
// NoiseKind::kRigid walks each body's pose instead: translation steps of std noise_std/sqrt(h)
// and rotation steps of that over the body's radius, applied to its vertices and centre together.
void make_noisy_sample(const Trajectory& trajectory, int frame, int history, double noise_std,
                       NoiseKind kind, double position_correction, std::mt19937_64& rng,
                       Scene& scene, Points& targets);

// Moves a sample made at frame − 1 (make_noisy_sample) on to `frame`, with the dynamic bodies'
// current poses taken from `predicted` (one per object of the trajectory: a model's own
// prediction from the sample) instead of the truth: their history drops its oldest step and ends
// at the prediction, kinematic objects take their true frames. The target rows are
// make_noisy_sample's with the prediction's error x'ᵗ − xᵗ in the place of the position noise:
// x^{t+1} − 2x'ᵗ + x̃^{t−1} + (1 − c)·(x'ᵗ − xᵗ), so that with c = 0 the model learns to give back
// the true velocity from its own error (the pushforward trick: training inputs from the
// distribution a rollout feeds the model, not only noise around the truth).
void advance_to_predicted(const Trajectory& trajectory, int frame, int history,
                          std::span<const Pose> predicted, double position_correction, Scene& scene,
                          Points& targets);

// Whether make_still_sample_in_air can use the trajectory: it has no kinematic objects (a pusher's
// motion could meet the lifted bodies, and the target would not be gravity alone).
bool can_hold_still_in_air(const Trajectory& trajectory);

// The gaps the trainer draws for still bodies in the air (log-uniform, metres), lowest vertex to
// floor. Bodies resting in `fignet generate`'s data lie with their lowest vertex 5 mm up (Bullet's
// collision margin, SceneSpec::collision_margin), so a 5 mm gap is resting contact and its
// free-fall target contradicts the data's; the smallest gap is that plus 1 cm, more than two steps
// of free fall at 48 Hz (g·dt² = 4.3 mm), so the target is right whatever the margin's exact value.
// The largest is far above the collision radius.
inline constexpr double kStillAirGaps[2] = {0.015, 2.0};

// A sample no trajectory holds: every body of the frame held still in the air and let go. Every
// dynamic body's history is its pose at `frame`, all lifted together so that the lowest vertex
// is `gap` metres above the floor (not lifted without a floor); the target is gravity·dt² for
// every vertex, as in free flight. Noise and its correction as in make_noisy_sample. MOVi throws
// its bodies, so nearly every still body in the data lies on something, and a model trained on
// it alone learns that still bodies stay still, in the air too. Throws ConfigError for a
// trajectory can_hold_still_in_air rejects or a gap that is not > 0.
void make_still_sample_in_air(const Trajectory& trajectory, int frame, int history, double gap,
                              double noise_std, NoiseKind kind, double position_correction,
                              std::mt19937_64& rng, Scene& scene, Points& targets);

// Turns a sample, its scene (see turn_about_vertical(double, Scene&)) and its target rows, by
// `angle` radians about the vertical axis through the floor's centre.
void turn_about_vertical(double angle, Scene& scene, Points& targets);

// What a body does in the truth around a sample's frame, as the loss weighs it.
enum BodyMotion : std::uint8_t { kMoving = 0, kResting = 1, kImpact = 2 };

// Per object of the trajectory: kResting where the body is dynamic and at rest in the truth
// around the sample, that is every vertex moves less than `max_step` metres over frame − 1 →
// frame and frame → frame + 1 (a body at the top of a free flight still moves g·dt/2 per step);
// kMoving elsewhere.
std::vector<std::uint8_t> resting_objects(const Trajectory& trajectory, int frame, double max_step);

// Marks kImpact on the dynamic bodies flagged kMoving that undergo an impact at the frame
// (is_impact).
void mark_impacts(const Trajectory& trajectory, int frame, double impact_g,
                  std::vector<std::uint8_t>& motion);

// Stacks per-scene targets into graph row order (each scene's floor nodes get zero rows) and
// marks which rows count in the loss (dynamic nodes).
void gather_targets(const Graph& graph, const std::vector<Points>& scene_targets,
                    RowMatrixXf& targets, std::vector<std::uint8_t>& in_loss);

// Each node's weight in the loss, in graph row order: 0 for kinematic nodes, `rest_weight` for
// the nodes of objects flagged kResting in `scene_motion` (per scene, per object as
// resting_objects and mark_impacts give), `impact_weight` for those flagged kImpact, 1 for the
// other dynamic nodes.
void gather_loss_weights(const Graph& graph,
                         const std::vector<std::vector<std::uint8_t>>& scene_motion,
                         float rest_weight, float impact_weight, std::vector<float>& weights);

}  // namespace fignet
