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

// An impact: the centre's acceleration departs from gravity by more than this many g (resting
// contact departs by one g). fignet eval's impacts and the training loss's impact weight.
inline constexpr double kImpactG = 2.0;

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

// Whether object `o` undergoes an impact at frame t: its centre's acceleration into the next
// frame, (x^{t+1} − 2x^t + x^{t−1}) / dt², departs from gravity by more than impact_g·|g|.
// Requires 1 <= t and t + 1 < num_frames().
bool is_impact(const Trajectory& trajectory, size_t o, int t, double impact_g);

}  // namespace fignet
