// A recorded rigid-body trajectory: rest meshes, static properties, kinematic flags and one pose
// per object per frame. What the data generator writes, training samples from, and rollouts are
// compared against.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fignet/graph/scene.h"

namespace fignet {

// Below this speed a body counts as at rest: fignet eval's rest regime (centre of mass) and the
// training loss's rest weight (every vertex) both use it.
inline constexpr double kRestSpeed = 0.05;  // m/s

struct TrajectoryObject {
  std::shared_ptr<const TriangleMesh> mesh;  // rest mesh in the centre-of-mass frame
  StaticProperties properties;
  // Principal moments of inertia (kg·m²) about the mesh frame's axes, when recorded: the mesh's
  // own uniform-density inertia differs from it when mass came from a convex hull, a shell or a
  // finer mesh than the one stored (fignet generate --assets).
  std::optional<Vec3> inertia;
  bool kinematic = false;
  std::vector<Pose> poses;  // one per frame
  // Per frame, when recorded (empty otherwise): centre-of-mass velocity and angular velocity.
  std::vector<Vec3> linear_velocities, angular_velocities;
};

struct Trajectory {
  std::vector<TrajectoryObject> objects;
  std::optional<Floor> floor;
  double time_step = 1.0 / 48.0;  // seconds between frames
  Vec3 gravity = Vec3(0, 0, -10);
  std::uint64_t seed = 0;  // the generator's seed for this trajectory

  int num_frames() const { return objects.empty() ? 0 : static_cast<int>(objects[0].poses.size()); }
  // Throws ConfigError when objects disagree on frame count or a pose is not finite.
  void validate() const;
};

// Fills `scene` with frames t-h … t of the trajectory (kinematic objects also get frame t+1),
// reusing its buffers. Requires h <= t and, for kinematic objects, t + 1 < num_frames().
void scene_at_frame(const Trajectory& trajectory, int t, int history, Scene& scene);

}  // namespace fignet
