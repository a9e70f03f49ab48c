// Stepping scenes forward with a predictor: x^{t+1} = a + 2x^t − x^{t−1} for dynamic nodes, then
// a rigid fit per object; kinematic objects follow their given poses.
#pragma once

#include <vector>

#include "fignet/data/trajectory.h"
#include "fignet/rollout/predictor.h"

namespace fignet {

// Reusable buffers of one stepping thread.
struct StepWorkspace {
  Points accelerations, predicted;
};

// The next pose of every object of `scene` (kinematic objects: their given next pose).
void predict_next_poses(AccelerationPredictor& predictor, const Scene& scene,
                        std::vector<Pose>& next, StepWorkspace& workspace);
// The integration half of predict_next_poses, for callers that ran the predictor themselves
// (FIGNetDynamicsWorld): workspace.accelerations holds one row per node of scene.objects.
void integrate_next_poses(const Scene& scene, std::vector<Pose>& next, StepWorkspace& workspace);

// Replays `truth` from its first h+1 frames: dynamic objects are predicted for frames h+1 …
// frames−1 (all frames when frames < 0), kinematic ones copied from `truth`. When given,
// `face_edges` receives the face–face edge count of each predicted step.
Trajectory rollout(AccelerationPredictor& predictor, const Trajectory& truth, int frames = -1,
                   std::vector<int>* face_edges = nullptr);

}  // namespace fignet
