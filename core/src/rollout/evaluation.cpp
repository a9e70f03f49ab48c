#include "fignet/rollout/evaluation.h"

#include <chrono>
#include <cmath>

#include "fignet/rollout/rollout.h"

namespace fignet {

Evaluation evaluate_rollouts(AccelerationPredictor& predictor, std::span<const Trajectory> truths,
                             const EvaluationOptions& options) {
  Evaluation result;
  result.trajectories = static_cast<int>(truths.size());
  if (truths.empty()) return result;
  double seconds = 0.0;
  PenetrationTotals penetration;
  long long steps = 0, edges = 0;
  std::vector<int> frame_counts;
  std::vector<int> face_edges;
  for (const Trajectory& truth : truths) {
    const auto start = std::chrono::steady_clock::now();
    const Trajectory predicted = rollout(predictor, truth, options.frames, &face_edges);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    steps += static_cast<long long>(face_edges.size());
    for (int e : face_edges) edges += e;
    const int first = predictor.history() + 1;
    RolloutErrors errors = rollout_errors(predicted, truth, first);
    // Per-frame means over the trajectories long enough to have that frame.
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
    if (options.penetration) penetration += penetration_totals(predicted, truth, first);
    result.per_trajectory.push_back(std::move(errors));
    if (options.on_trajectory)
      options.on_trajectory(static_cast<int>(result.per_trajectory.size()));
  }
  const double n = static_cast<double>(truths.size());
  for (size_t f = 0; f < result.translation.size(); ++f) {
    result.translation[f] /= frame_counts[f];
    result.rotation[f] /= frame_counts[f];
  }
  result.mean_translation /= n;
  result.final_translation /= n;
  result.mean_rotation /= n;
  result.final_rotation /= n;
  const PenetrationRatio ratio =
      options.penetration ? penetration.ratio() : PenetrationRatio{std::nan(""), std::nan("")};
  result.penetration_depth_ratio = ratio.depth;
  result.penetration_count_ratio = ratio.count;
  result.face_edges_per_step = steps > 0 ? static_cast<double>(edges) / steps : 0.0;
  result.milliseconds_per_step = steps > 0 ? 1e3 * seconds / steps : 0.0;
  return result;
}

}  // namespace fignet
