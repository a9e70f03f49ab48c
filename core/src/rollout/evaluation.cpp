#include "fignet/rollout/evaluation.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <limits>

#include "fignet/error.h"
#include "fignet/rollout/rollout.h"
#include "per_trajectory_threads.h"

namespace fignet {

EvaluationTotals evaluate_rollout_totals(AccelerationPredictor& predictor,
                                         std::span<const Trajectory> truths,
                                         const EvaluationOptions& options) {
  EvaluationTotals totals;
  std::vector<int> face_edges;
  for (const Trajectory& truth : truths) {
    const auto start = std::chrono::steady_clock::now();
    const Trajectory predicted = rollout(predictor, truth, options.frames, &face_edges);
    totals.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    totals.steps += static_cast<long long>(face_edges.size());
    for (int e : face_edges) totals.face_edges += e;
    const int first = predictor.history() + 1;
    totals.per_trajectory.push_back(rollout_errors(predicted, truth, first));
    if (options.penetration) totals.penetration += penetration_totals(predicted, truth, first);
    if (options.on_trajectory) {
      options.on_trajectory(static_cast<int>(totals.per_trajectory.size()));
    }
  }
  return totals;
}

Evaluation summarize(const EvaluationTotals& totals, const EvaluationOptions& options) {
  Evaluation result;
  result.trajectories = static_cast<int>(totals.per_trajectory.size());
  if (result.trajectories == 0) return result;
  // Per-frame means over the trajectories long enough to have that frame.
  std::vector<int> frame_counts;
  double predicted_travel = 0.0, true_travel = 0.0;
  for (const RolloutErrors& errors : totals.per_trajectory) {
    const size_t frames = errors.translation.size();
    if (result.translation.size() < frames) {
      result.translation.resize(frames, 0.0);
      result.rotation.resize(frames, 0.0);
      frame_counts.resize(frames, 0);
    }
    for (size_t f = 0; f < frames; ++f) {
      result.translation[f] += errors.translation[f];
      result.rotation[f] += errors.rotation[f];
      ++frame_counts[f];
    }
    result.mean_translation += errors.mean_translation;
    result.final_translation += errors.final_translation;
    result.mean_rotation += errors.mean_rotation;
    result.final_rotation += errors.final_rotation;
    predicted_travel += errors.predicted_travel;
    true_travel += errors.true_travel;
  }
  result.travel_ratio =
      true_travel > 0.0 ? predicted_travel / true_travel : std::numeric_limits<double>::quiet_NaN();
  const double n = result.trajectories;
  for (size_t f = 0; f < result.translation.size(); ++f) {
    result.translation[f] /= frame_counts[f];
    result.rotation[f] /= frame_counts[f];
  }
  result.mean_translation /= n;
  result.final_translation /= n;
  result.mean_rotation /= n;
  result.final_rotation /= n;
  const PenetrationRatio ratio = options.penetration ? totals.penetration.ratio()
                                                     : PenetrationRatio{std::nan(""), std::nan("")};
  result.penetration_depth_ratio = ratio.depth;
  result.penetration_count_ratio = ratio.count;
  const double steps = static_cast<double>(totals.steps);
  result.face_edges_per_step = steps > 0 ? static_cast<double>(totals.face_edges) / steps : 0.0;
  result.milliseconds_per_step = steps > 0 ? 1e3 * totals.seconds / steps : 0.0;
  result.per_trajectory = totals.per_trajectory;
  return result;
}

Evaluation evaluate_rollouts(AccelerationPredictor& predictor, std::span<const Trajectory> truths,
                             const EvaluationOptions& options) {
  return summarize(evaluate_rollout_totals(predictor, truths, options), options);
}

Evaluation evaluate_rollouts_parallel(
    const std::function<std::unique_ptr<AccelerationPredictor>()>& make_predictor,
    std::span<const Trajectory> truths, int threads, const EvaluationOptions& options) {
  EvaluationOptions quiet = options;
  quiet.on_trajectory = nullptr;
  std::vector<EvaluationTotals> each(truths.size());
  detail::for_each_trajectory(make_predictor, static_cast<int>(truths.size()), threads,
                              [&](AccelerationPredictor& predictor, int i) {
                                each[i] =
                                    evaluate_rollout_totals(predictor, truths.subspan(i, 1), quiet);
                              });
  EvaluationTotals totals;
  for (const EvaluationTotals& t : each) totals += t;
  return summarize(totals, options);
}

EvaluationTotals& EvaluationTotals::operator+=(const EvaluationTotals& other) {
  per_trajectory.insert(per_trajectory.end(), other.per_trajectory.begin(),
                        other.per_trajectory.end());
  penetration += other.penetration;
  steps += other.steps;
  face_edges += other.face_edges;
  seconds += other.seconds;
  return *this;
}

// [trajectories, steps, face edges, seconds, 4 penetration totals, then per trajectory: frames,
// translation…, rotation…, mean and final translation, mean and final rotation, predicted and
// true travel].
std::vector<double> EvaluationTotals::serialize() const {
  std::vector<double> out = {static_cast<double>(per_trajectory.size()),
                             static_cast<double>(steps),
                             static_cast<double>(face_edges),
                             seconds,
                             penetration.predicted_depth,
                             penetration.truth_depth,
                             penetration.predicted_count,
                             penetration.truth_count};
  for (const RolloutErrors& e : per_trajectory) {
    out.push_back(static_cast<double>(e.translation.size()));
    out.insert(out.end(), e.translation.begin(), e.translation.end());
    out.insert(out.end(), e.rotation.begin(), e.rotation.end());
    out.insert(out.end(), {e.mean_translation, e.final_translation, e.mean_rotation,
                           e.final_rotation, e.predicted_travel, e.true_travel});
  }
  return out;
}

EvaluationTotals EvaluationTotals::deserialize(std::span<const double> values, size_t* consumed) {
  size_t at = 0;
  const auto next = [&]() {
    if (at >= values.size()) throw ConfigError("evaluation totals: truncated");
    return values[at++];
  };
  EvaluationTotals totals;
  const auto count = static_cast<size_t>(next());
  totals.steps = static_cast<long long>(next());
  totals.face_edges = static_cast<long long>(next());
  totals.seconds = next();
  totals.penetration = {next(), next(), next(), next()};
  for (size_t t = 0; t < count; ++t) {
    RolloutErrors e;
    const auto frames = static_cast<size_t>(next());
    for (size_t f = 0; f < frames; ++f) e.translation.push_back(next());
    for (size_t f = 0; f < frames; ++f) e.rotation.push_back(next());
    e.mean_translation = next();
    e.final_translation = next();
    e.mean_rotation = next();
    e.final_rotation = next();
    e.predicted_travel = next();
    e.true_travel = next();
    totals.per_trajectory.push_back(std::move(e));
  }
  if (consumed) *consumed = at;
  return totals;
}

}  // namespace fignet
