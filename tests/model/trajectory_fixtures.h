// Analytic trajectories for model tests: free flight with constant spin, and a kinematic pusher.
#pragma once

#include <memory>

#include "fignet/data/trajectory.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"

namespace fignet::testing {

// A body in free flight: p(t) = p0 + v t + ½ g t², orientation spinning at `spin` rad/s.
inline TrajectoryObject ballistic_object(std::shared_ptr<const TriangleMesh> mesh, const Vec3& p0,
                                         const Vec3& v, const Vec3& spin, int frames, double dt,
                                         const Vec3& gravity) {
  TrajectoryObject object;
  object.mesh = std::move(mesh);
  object.properties = {1.0, 0.5, 0.5};
  for (int f = 0; f < frames; ++f) {
    const double t = f * dt;
    Pose pose;
    pose.position = p0 + v * t + 0.5 * gravity * t * t;
    const Vec3 angle = spin * t;
    pose.orientation = angle.norm() > 0
                           ? Eigen::Quaterniond(Eigen::AngleAxisd(angle.norm(), angle.normalized()))
                           : Eigen::Quaterniond::Identity();
    object.poses.push_back(pose);
  }
  return object;
}

inline std::shared_ptr<const TriangleMesh> small_cube(double half = 0.2) {
  return std::make_shared<const TriangleMesh>(
      centered_on_center_of_mass(make_box(Vec3::Constant(half), 1)));
}

}  // namespace fignet::testing
