#include "fignet/train/training_batch.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "fignet/error.h"

namespace fignet {

std::vector<SampleRef> enumerate_samples(const std::vector<Trajectory>& data, int history) {
  std::vector<SampleRef> samples;
  for (size_t i = 0; i < data.size(); ++i) {
    for (int t = history; t + 1 < data[i].num_frames(); ++t) samples.push_back({int(i), t});
  }
  return samples;
}

namespace {

// Adds random-walk noise to the history of one dynamic object (see make_noisy_sample) and
// returns the noise left on its current positions.
Points add_history_noise(SceneObject& object, int history, double noise_std, NoiseKind kind,
                         std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, noise_std / std::sqrt(static_cast<double>(history)));
  const Eigen::Index v = object.mesh->num_vertices();
  // Random walk over the history steps: noise[k] = Σ_{j<=k} velocity noise, noise[0] = 0.
  Points noise = Points::Zero(v, 3);
  if (kind == NoiseKind::kVertex) {
    for (int k = 1; k <= history; ++k) {
      if (noise_std > 0.0) {
        for (Eigen::Index i = 0; i < noise.size(); ++i) noise.data()[i] += normal(rng);
      }
      object.positions.middleRows(k * v, v) += noise;
    }
    return noise;
  }
  // The body's pose walks: a translation and a rotation about its centre, scaled so that its
  // farthest vertex moves by about the translation's amount.
  const double radius = std::max(object.mesh->vertices().rowwise().norm().maxCoeff(), 1e-3);
  Vec3 translation = Vec3::Zero(), rotation = Vec3::Zero();
  for (int k = 1; k <= history; ++k) {
    if (noise_std > 0.0) {
      for (int c = 0; c < 3; ++c) translation[c] += normal(rng);
      for (int c = 0; c < 3; ++c) rotation[c] += normal(rng) / radius;
    }
    const Vec3 center = object.centers.row(k).transpose();
    const Eigen::Matrix3d turn =
        rotation.norm() > 0.0
            ? Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).toRotationMatrix()
            : Eigen::Matrix3d::Identity();
    auto step = object.positions.middleRows(k * v, v);
    for (Eigen::Index i = 0; i < v; ++i) {
      const Vec3 x = step.row(i).transpose();
      const Vec3 moved = center + turn * (x - center) + translation;
      noise.row(i) = (moved - x).transpose();
      step.row(i) = moved.transpose();
    }
    object.centers.row(k) += translation.transpose();
  }
  return noise;
}

// Sizes `targets` to one zero row per node of the scene and calls fill(o, object, rows) with
// each object's block of them.
template <typename Fill>
void fill_target_rows(Scene& scene, Points& targets, const Fill& fill) {
  targets.setZero(scene.num_nodes(), 3);
  Eigen::Index row = 0;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const Eigen::Index v = scene.objects[o].mesh->num_vertices();
    fill(o, scene.objects[o], targets.middleRows(row, v));
    row += v;
  }
}

// Noise on every dynamic object's history, and its target rows from its clean next positions
// (`clean_next(o)`): the velocity noise is undone, and the share `position_correction` of the
// last position's noise too (the rest is kept).
template <typename CleanNext>
void add_noise_and_targets(Scene& scene, int history, double noise_std, NoiseKind kind,
                           double position_correction, std::mt19937_64& rng,
                           const CleanNext& clean_next, Points& targets) {
  fill_target_rows(scene, targets, [&](size_t o, SceneObject& object, auto rows) {
    if (object.kinematic) return;
    const Points noise = add_history_noise(object, history, noise_std, kind, rng);
    rows = clean_next(o) - 2.0 * object.positions_at(history) + object.positions_at(history - 1) +
           (1.0 - position_correction) * noise;
  });
}

}  // namespace

void make_noisy_sample(const Trajectory& trajectory, int frame, int history, double noise_std,
                       NoiseKind kind, double position_correction, std::mt19937_64& rng,
                       Scene& scene, Points& targets) {
  scene_at_frame(trajectory, frame, history, scene);
  add_noise_and_targets(
      scene, history, noise_std, kind, position_correction, rng,
      [&](size_t o) {
        return posed_vertices(*scene.objects[o].mesh, trajectory.objects[o].poses[frame + 1]);
      },
      targets);
}

void advance_to_predicted(const Trajectory& trajectory, int frame, int history,
                          std::span<const Pose> predicted, double position_correction, Scene& scene,
                          Points& targets) {
  if (predicted.size() != trajectory.objects.size() || scene.objects.size() != predicted.size()) {
    throw ConfigError(fmt::format(
        "advance_to_predicted: {} predicted poses and {} scene objects for {} trajectory objects",
        predicted.size(), scene.objects.size(), trajectory.objects.size()));
  }
  if (history < 1 || frame < history + 1 || frame + 1 >= trajectory.num_frames()) {
    throw ConfigError(fmt::format(
        "advance_to_predicted: frame {} with history {} (needs history >= 1 and a frame in {} .. "
        "{}: one before the history and one after)",
        frame, history, history + 1, trajectory.num_frames() - 2));
  }
  fill_target_rows(scene, targets, [&](size_t o, SceneObject& object, auto rows) {
    const TrajectoryObject& truth = trajectory.objects[o];
    if (object.kinematic) {
      const std::span<const Pose> poses(truth.poses);
      set_pose_history(object, poses.subspan(frame - history, history + 1), poses[frame + 1]);
      return;
    }
    // The noisy history slides one step older and ends at the prediction.
    const Eigen::Index v = object.mesh->num_vertices();
    for (int k = 0; k < history; ++k) {
      object.positions.middleRows(k * v, v) = object.positions.middleRows((k + 1) * v, v).eval();
      object.centers.row(k) = object.centers.row(k + 1).eval();
    }
    const Points now = posed_vertices(*object.mesh, predicted[o]);
    const Points error = now - posed_vertices(*object.mesh, truth.poses[frame]);
    object.positions.middleRows(history * v, v) = now;
    object.centers.row(history) = predicted[o].position.transpose();
    rows = posed_vertices(*object.mesh, truth.poses[frame + 1]) - 2.0 * now +
           object.positions_at(history - 1) + (1.0 - position_correction) * error;
  });
}

bool can_hold_still_in_air(const Trajectory& trajectory) {
  return std::none_of(trajectory.objects.begin(), trajectory.objects.end(),
                      [](const TrajectoryObject& object) { return object.kinematic; });
}

void make_still_sample_in_air(const Trajectory& trajectory, int frame, int history, double gap,
                              double noise_std, NoiseKind kind, double position_correction,
                              std::mt19937_64& rng, Scene& scene, Points& targets) {
  if (!can_hold_still_in_air(trajectory)) {
    throw ConfigError(
        "make_still_sample_in_air: the trajectory has kinematic objects, whose "
        "motion could meet the lifted bodies");
  }
  if (!(gap > 0.0) || !std::isfinite(gap)) {
    throw ConfigError(fmt::format("make_still_sample_in_air: gap = {} (must be > 0)", gap));
  }
  scene_at_frame(trajectory, frame, history, scene);
  // One lift for all the bodies keeps them as they lie on each other.
  double lowest = std::numeric_limits<double>::infinity();
  for (const SceneObject& object : scene.objects) {
    lowest = std::min(lowest, object.positions_at(history).col(2).minCoeff());
  }
  const double lift = scene.floor ? scene.floor->height + gap - lowest : 0.0;
  std::vector<Pose> lifted(scene.objects.size());
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    lifted[o] = trajectory.objects[o].poses[frame];
    lifted[o].position.z() += lift;
    const std::vector<Pose> still(static_cast<size_t>(history) + 1, lifted[o]);
    set_pose_history(scene.objects[o], still);
  }
  // Nothing holds them: each vertex falls by gravity·dt² over the step, as in free flight.
  const Vec3 fall = trajectory.gravity * trajectory.time_step * trajectory.time_step;
  add_noise_and_targets(
      scene, history, noise_std, kind, position_correction, rng,
      [&](size_t o) -> Points {
        return posed_vertices(*scene.objects[o].mesh, lifted[o]).rowwise() + fall.transpose();
      },
      targets);
}

void turn_about_vertical(double angle, Scene& scene, Points& targets) {
  turn_about_vertical(angle, scene);
  // Accelerations are directions: no axis.
  targets = targets * Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix().transpose();
}

std::vector<std::uint8_t> resting_objects(const Trajectory& trajectory, int frame,
                                          double max_step) {
  std::vector<std::uint8_t> resting(trajectory.objects.size(), 0);
  if (frame < 1 || frame + 1 >= trajectory.num_frames()) return resting;
  for (size_t o = 0; o < trajectory.objects.size(); ++o) {
    const TrajectoryObject& object = trajectory.objects[o];
    if (object.kinematic) continue;
    const Points before = posed_vertices(*object.mesh, object.poses[frame - 1]);
    const Points now = posed_vertices(*object.mesh, object.poses[frame]);
    const Points after = posed_vertices(*object.mesh, object.poses[frame + 1]);
    const double moved = std::max((now - before).rowwise().norm().maxCoeff(),
                                  (after - now).rowwise().norm().maxCoeff());
    resting[o] = moved < max_step ? kResting : kMoving;
  }
  return resting;
}

void mark_impacts(const Trajectory& trajectory, int frame, double impact_g,
                  std::vector<std::uint8_t>& motion) {
  if (motion.size() != trajectory.objects.size()) {
    throw ConfigError(fmt::format("mark_impacts: {} flags for {} objects", motion.size(),
                                  trajectory.objects.size()));
  }
  if (frame < 1 || frame + 1 >= trajectory.num_frames()) return;
  for (size_t o = 0; o < trajectory.objects.size(); ++o) {
    if (trajectory.objects[o].kinematic || motion[o] != kMoving) continue;
    if (is_impact(trajectory, o, frame, impact_g)) motion[o] = kImpact;
  }
}

void gather_targets(const Graph& graph, const std::vector<Points>& scene_targets,
                    RowMatrixXf& targets, std::vector<std::uint8_t>& in_loss) {
  targets.setZero(graph.num_mesh_nodes(), 3);
  in_loss.assign(graph.num_mesh_nodes(), 0);
  for (int s = 0; s < graph.num_scenes(); ++s) {
    const int first_node = graph.object_first_node[graph.scene_first_object[s]];
    const Points& t = scene_targets[s];
    targets.middleRows(first_node, t.rows()) = t.cast<float>();
    for (Eigen::Index i = 0; i < t.rows(); ++i) {
      in_loss[first_node + i] = graph.node_kinematic[first_node + i] ? 0 : 1;
    }
  }
}

void gather_loss_weights(const Graph& graph,
                         const std::vector<std::vector<std::uint8_t>>& scene_motion,
                         float rest_weight, float impact_weight, std::vector<float>& weights) {
  weights.assign(graph.num_mesh_nodes(), 0.0f);
  for (int s = 0; s < graph.num_scenes(); ++s) {
    const int first_object = graph.scene_first_object[s];
    const std::vector<std::uint8_t>& motion = scene_motion[s];
    for (size_t o = 0; o < motion.size(); ++o) {
      const int object = first_object + static_cast<int>(o);
      const float weight = motion[o] == kResting  ? rest_weight
                           : motion[o] == kImpact ? impact_weight
                                                  : 1.0f;
      for (int i = graph.object_first_node[object]; i < graph.object_first_node[object + 1]; ++i) {
        weights[i] = graph.node_kinematic[i] ? 0.0f : weight;
      }
    }
  }
}

}  // namespace fignet
