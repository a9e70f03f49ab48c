// Rollout accuracy as public FIGNet re-implementations report it (facts §3): translation error
// (RMSE over dynamic objects of the centre-of-mass error, metres) and rotation error (mean over
// dynamic objects of the relative rotation angle, degrees), per frame, with their mean over the
// predicted frames and their value at the last one; and a penetration measure.
#pragma once

#include <vector>

#include "fignet/data/trajectory.h"

namespace fignet {

struct RolloutErrors {
  std::vector<double> translation;  // per frame, metres (0 for the given initial frames)
  std::vector<double> rotation;     // per frame, degrees
  double mean_translation = 0, final_translation = 0;  // over frames first_predicted … end
  double mean_rotation = 0, final_rotation = 0;
  // Distance the dynamic objects' centres travel over the predicted frames (each frame's step
  // from the one before, summed over objects), in the rollout and in the truth, metres: their
  // ratio tells a model that slows bodies too much (< 1) or keeps them going (> 1), which the
  // errors above do not.
  double predicted_travel = 0, true_travel = 0;
};

// Compares a rollout with the truth over frames [first_predicted, end).
RolloutErrors rollout_errors(const Trajectory& predicted, const Trajectory& truth,
                             int first_predicted);

// Angle of q_a⁻¹·q_b in degrees, in [0, 180].
double rotation_angle_degrees(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

struct Penetration {
  int intersecting_face_pairs = 0;  // face pairs of different objects that cross
  double depth = 0.0;  // Σ over vertices inside another object (or below the floor) of their depth
};

// Penetration of one frame. Objects must be closed meshes for the inside test.
Penetration measure_penetration(const Trajectory& trajectory, int frame);

// Seed table H.1: penetration of a rollout as a ratio to the ground truth's on the same scene,
// summed over frames [first, end): depth ratio and crossing-face-pair count ratio (NaN where the
// ground truth has none).
struct PenetrationRatio {
  double depth = 0.0, count = 0.0;
};
// Penetration sums of a rollout and of its ground truth, which add up over a set of scenes so a
// set's ratio is not dominated by scenes whose ground truth barely touches.
struct PenetrationTotals {
  double predicted_depth = 0, truth_depth = 0, predicted_count = 0, truth_count = 0;
  PenetrationTotals& operator+=(const PenetrationTotals& other);
  PenetrationRatio ratio() const;
};
PenetrationTotals penetration_totals(const Trajectory& predicted, const Trajectory& truth,
                                     int first);
PenetrationRatio penetration_ratio(const Trajectory& predicted, const Trajectory& truth, int first);

}  // namespace fignet
