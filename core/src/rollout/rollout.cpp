#include "fignet/rollout/rollout.h"

#include "fignet/rollout/rigid_fit.h"

namespace fignet {

namespace {

// A kinematic object's next pose, recovered from its given next node positions.
Pose next_kinematic_pose(const SceneObject& object) {
  return fit_rigid_transform(object.mesh->vertices(), object.next_positions);
}

}  // namespace

void predict_next_poses(AccelerationPredictor& predictor, const Scene& scene,
                        std::vector<Pose>& next, StepWorkspace& workspace) {
  predictor.predict(scene, workspace.accelerations);
  integrate_next_poses(scene, next, workspace);
}

void integrate_next_poses(const Scene& scene, std::vector<Pose>& next, StepWorkspace& workspace) {
  next.resize(scene.objects.size());
  Eigen::Index row = 0;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const SceneObject& object = scene.objects[o];
    const int v = object.mesh->num_vertices();
    const int steps = object.num_steps();
    if (object.kinematic) {
      next[o] = next_kinematic_pose(object);
    } else {
      // Finite-difference integration of each node, then the closest rigid motion.
      workspace.predicted = workspace.accelerations.middleRows(row, v) +
                            2.0 * object.positions_at(steps - 1) - object.positions_at(steps - 2);
      next[o] = fit_rigid_transform(object.mesh->vertices(), workspace.predicted);
    }
    row += v;
  }
}

Trajectory rollout(AccelerationPredictor& predictor, const Trajectory& truth, int frames,
                   std::vector<int>* face_edges) {
  truth.validate();
  const int total = frames < 0 ? truth.num_frames() : std::min(frames, truth.num_frames());
  const int h = predictor.history();
  Trajectory predicted = truth;
  Scene scene;
  StepWorkspace workspace;
  std::vector<Pose> next;
  if (face_edges) face_edges->clear();
  for (int t = h; t + 1 < total; ++t) {
    scene_at_frame(predicted, t, h, scene);
    predict_next_poses(predictor, scene, next, workspace);
    if (face_edges) face_edges->push_back(predictor.last_face_edges());
    for (size_t o = 0; o < predicted.objects.size(); ++o) {
      if (!predicted.objects[o].kinematic) predicted.objects[o].poses[t + 1] = next[o];
    }
  }
  for (auto& object : predicted.objects) object.poses.resize(total);
  return predicted;
}

}  // namespace fignet
