// Native Bullet simulation of a SceneSpec: a btDiscreteDynamicsWorld with Kubric's solver settings,
// convex-hull bodies and a static plane floor. Ground truth for datasets and for comparisons.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "fignet/bullet/scene_spec.h"

class btBroadphaseInterface;
class btCollisionConfiguration;
class btConstraintSolver;
class btDiscreteDynamicsWorld;
class btDispatcher;
class btRigidBody;

namespace fignet::bullet {

// Solver settings that Kubric's PyBullet scenes use, where Bullet exposes them (facts §1).
struct SolverSettings {
  int iterations = 10;
  bool split_impulse = true;
  bool warm_starting = false;
  double restitution_velocity_threshold = 0.0;
  double linear_slop = 0.0;
  // Bullet steps per recorded frame; 0 takes the scene's (240 Hz: 5 per 48 Hz frame). 1 steps
  // once per frame: coarse native Bullet, or a FIGNet world at the model's rate.
  int steps_per_frame = 0;
};

// Makes the world the scene is simulated in (for example a FIGNetDynamicsWorld); none gives a
// btDiscreteDynamicsWorld.
using WorldFactory = std::function<std::unique_ptr<btDiscreteDynamicsWorld>(
    btDispatcher*, btBroadphaseInterface*, btConstraintSolver*, btCollisionConfiguration*)>;

class BulletSimulation {
 public:
  explicit BulletSimulation(const SceneSpec& spec, const SolverSettings& settings = {},
                            const WorldFactory& make_world = {});
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
