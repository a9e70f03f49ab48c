#include "fignet/data/trajectory.h"

#include <fmt/format.h>

#include "fignet/error.h"

namespace fignet {

void Trajectory::validate() const {
  const int frames = num_frames();
  for (size_t o = 0; o < objects.size(); ++o) {
    const TrajectoryObject& object = objects[o];
    if (!object.mesh) throw ConfigError(fmt::format("trajectory object {}: has no mesh", o));
    if (static_cast<int>(object.poses.size()) != frames) {
      throw ConfigError(fmt::format("trajectory object {}: has {} poses, object 0 has {}", o,
                                    object.poses.size(), frames));
    }
    for (size_t f = 0; f < object.poses.size(); ++f) {
      if (!object.poses[f].position.allFinite() ||
          !object.poses[f].orientation.coeffs().allFinite()) {
        throw ConfigError(fmt::format("trajectory object {}: pose {} is not finite", o, f));
      }
    }
  }
}

void scene_at_frame(const Trajectory& trajectory, int t, int history, Scene& scene) {
  if (t < history || t >= trajectory.num_frames()) {
    throw ConfigError(fmt::format("frame {} has no history of {} frames in a trajectory of {}", t,
                                  history, trajectory.num_frames()));
  }
  scene.objects.resize(trajectory.objects.size());
  scene.floor = trajectory.floor;
  for (size_t o = 0; o < trajectory.objects.size(); ++o) {
    const TrajectoryObject& source = trajectory.objects[o];
    SceneObject& object = scene.objects[o];
    object.mesh = source.mesh.get();
    object.properties = source.properties;
    object.kinematic = source.kinematic;
    std::optional<Pose> next;
    if (source.kinematic) {
      if (t + 1 >= trajectory.num_frames()) {
        throw ConfigError(fmt::format("kinematic object {} has no pose after frame {}", o, t));
      }
      next = source.poses[t + 1];
    }
    set_pose_history(object, std::span(source.poses).subspan(t - history, history + 1), next);
  }
}

bool is_impact(const Trajectory& trajectory, size_t o, int t, double impact_g) {
  const std::vector<Pose>& poses = trajectory.objects[o].poses;
  const double dt = trajectory.time_step;
  const Vec3 acceleration =
      (poses[t + 1].position - 2.0 * poses[t].position + poses[t - 1].position) / (dt * dt);
  return (acceleration - trajectory.gravity).norm() > impact_g * trajectory.gravity.norm();
}

}  // namespace fignet
