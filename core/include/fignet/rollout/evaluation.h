// Rollouts of one predictor over a set of trajectories, summarised the way `fignet eval` and the
// training validation report them: errors per frame and over the rollout, penetration against the
// ground truth, face–face edges and time per step.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "fignet/rollout/metrics.h"
#include "fignet/rollout/predictor.h"

namespace fignet {

struct EvaluationOptions {
  int frames = -1;           // rollout length (all frames when < 0)
  bool penetration = false;  // also measure penetration ratios (costly: winding numbers)
  std::function<void(int done)> on_trajectory;  // progress: called after each rollout
};

struct Evaluation {
  int trajectories = 0;
  // Per frame, mean over trajectories (frames 0 … h are given, so 0).
  std::vector<double> translation, rotation;
  // Over trajectories: mean of each rollout's mean error and of its last-frame error.
  double mean_translation = 0, final_translation = 0, mean_rotation = 0, final_rotation = 0;
  // The distance the bodies travel in the rollouts over the distance they travel in the truth,
  // both summed over every trajectory (RolloutErrors::predicted_travel); NaN when nothing moves.
  double travel_ratio = 0;
  // Penetration of the rollouts as a ratio to the ground truth's (seed H.1); NaN if not measured
  // or when the ground truth has none.
  double penetration_depth_ratio = 0, penetration_count_ratio = 0;
  double face_edges_per_step = 0;    // mean over every predicted step
  double milliseconds_per_step = 0;  // wall time of predicting one step, graph included
  std::vector<RolloutErrors> per_trajectory;
};

Evaluation evaluate_rollouts(AccelerationPredictor& predictor, std::span<const Trajectory> truths,
                             const EvaluationOptions& options = {});
// The same with the trajectories shared among `threads` threads, each with a predictor of its own
// from `make_predictor`; results are combined in trajectory order, so they equal the one-thread
// evaluation's (on_trajectory is not called).
Evaluation evaluate_rollouts_parallel(
    const std::function<std::unique_ptr<AccelerationPredictor>()>& make_predictor,
    std::span<const Trajectory> truths, int threads, const EvaluationOptions& options = {});

// The same in two halves, for evaluations split across processes: each rolls out its share into
// totals, the totals are concatenated (in trajectory order) and summarised once.
struct EvaluationTotals {
  std::vector<RolloutErrors> per_trajectory;
  PenetrationTotals penetration;
  long long steps = 0, face_edges = 0;
  double seconds = 0.0;
  EvaluationTotals& operator+=(const EvaluationTotals& other);
  // Flat form for sending between processes, and back.
  std::vector<double> serialize() const;
  // Reads one serialized totals from the front of `values`; `consumed` (if given) tells how many
  // values it took, so concatenated ones can be read in turn.
  static EvaluationTotals deserialize(std::span<const double> values, size_t* consumed = nullptr);
};
EvaluationTotals evaluate_rollout_totals(AccelerationPredictor& predictor,
                                         std::span<const Trajectory> truths,
                                         const EvaluationOptions& options = {});
Evaluation summarize(const EvaluationTotals& totals, const EvaluationOptions& options = {});

}  // namespace fignet
