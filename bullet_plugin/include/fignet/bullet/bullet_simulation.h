// Native Bullet simulation of a SceneSpec: a btDiscreteDynamicsWorld with Kubric's solver settings,
// convex-hull bodies and a static plane floor. Ground truth for datasets and for comparisons.
#pragma once

#include <memory>
#include <vector>

#include "fignet/bullet/scene_spec.h"

class btDiscreteDynamicsWorld;
class btRigidBody;

namespace fignet::bullet {

// Solver settings that Kubric's PyBullet scenes use, where Bullet exposes them (facts §1).
struct SolverSettings {
  int iterations = 10;
  bool split_impulse = true;
  bool warm_starting = false;
  double restitution_velocity_threshold = 0.0;
  double linear_slop = 0.0;
};

class BulletSimulation {
 public:
  explicit BulletSimulation(const SceneSpec& spec, const SolverSettings& settings = {});
  ~BulletSimulation();
  BulletSimulation(const BulletSimulation&) = delete;
  BulletSimulation& operator=(const BulletSimulation&) = delete;

  // Advances one frame (spec.steps_per_frame fixed Bullet steps).
  void step_frame();
  Pose pose(int body) const;
  Vec3 linear_velocity(int body) const;
  Vec3 angular_velocity(int body) const;
  btDiscreteDynamicsWorld& world();

  // Runs all spec.frames frames and records them (frame 0 = the initial state).
  Trajectory record();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fignet::bullet
