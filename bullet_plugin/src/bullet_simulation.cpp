#include "fignet/bullet/bullet_simulation.h"

#include <btBulletDynamicsCommon.h>

#include "fignet/bullet/conversions.h"
#include "fignet/bullet/rigid_bodies.h"
#include "fignet/error.h"

namespace fignet::bullet {

namespace {

// Pose of a kinematic body moving with constant linear and angular velocity for `seconds`.
Pose scripted_pose(const BodySpec& body, double seconds) {
  Pose pose = body.pose;
  pose.position += body.linear_velocity * seconds;
  const Vec3 angle = body.angular_velocity * seconds;
  if (angle.norm() > 0) {
    pose.orientation = Eigen::AngleAxisd(angle.norm(), angle.normalized()) * body.pose.orientation;
  }
  return pose;
}

}  // namespace

struct BulletSimulation::Impl {
  SceneSpec spec;
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  std::unique_ptr<btDiscreteDynamicsWorld> world;
  std::unique_ptr<RigidBodies> bodies;  // spec order; the floor, if any, last
  int steps_per_frame = 1;
  long long steps = 0;

  ~Impl() { bodies.reset(); }  // before the world
};

BulletSimulation::BulletSimulation(const SceneSpec& spec, const SolverSettings& settings,
                                   const WorldFactory& make_world)
    : impl_(std::make_unique<Impl>()) {
  impl_->spec = spec;
  Impl& impl = *impl_;
  impl.world =
      make_world ? make_world(&impl.dispatcher, &impl.broadphase, &impl.solver, &impl.configuration)
                 : std::make_unique<btDiscreteDynamicsWorld>(&impl.dispatcher, &impl.broadphase,
                                                             &impl.solver, &impl.configuration);
  impl.bodies = std::make_unique<RigidBodies>(*impl.world);
  impl.steps_per_frame =
      settings.steps_per_frame > 0 ? settings.steps_per_frame : spec.steps_per_frame;
  btDiscreteDynamicsWorld& world = *impl.world;
  world.setGravity(to_bt(spec.gravity));
  btContactSolverInfo& info = world.getSolverInfo();
  info.m_numIterations = settings.iterations;
  info.m_splitImpulse = settings.split_impulse;
  if (!settings.warm_starting) info.m_solverMode &= ~SOLVER_USE_WARMSTARTING;
  info.m_restitutionVelocityThreshold = btScalar(settings.restitution_velocity_threshold);
  info.m_linearSlop = btScalar(settings.linear_slop);

  for (const BodySpec& body : spec.bodies) {
    btRigidBody* rigid = impl.bodies->add(body, spec.collision_margin);
    rigid->setActivationState(DISABLE_DEACTIVATION);  // datasets record every body every frame
  }
  if (spec.floor) {
    auto plane =
        std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), btScalar(spec.floor->height));
    btRigidBody* floor =
        impl.bodies->add(std::move(plane), 0.0, btVector3(0, 0, 0), btTransform::getIdentity());
    floor->setFriction(btScalar(spec.floor->properties.friction));
    floor->setRestitution(btScalar(spec.floor->properties.restitution));
  }
}

BulletSimulation::~BulletSimulation() = default;

btDiscreteDynamicsWorld& BulletSimulation::world() {
  return *impl_->world;
}

void BulletSimulation::step_frame() {
  const SceneSpec& spec = impl_->spec;
  const int steps = impl_->steps_per_frame;
  const double step = spec.frame_step() / steps;
  for (int s = 0; s < steps; ++s) {
    ++impl_->steps;
    // Kinematic bodies follow their script through their motion state (Bullet derives their
    // velocity from the change of pose).
    for (size_t i = 0; i < spec.bodies.size(); ++i) {
      if (!spec.bodies[i].kinematic) continue;
      (*impl_->bodies)[static_cast<int>(i)].getMotionState()->setWorldTransform(
          to_bt(scripted_pose(spec.bodies[i], impl_->steps * step)));
    }
    impl_->world->stepSimulation(btScalar(step), 0, btScalar(step));
  }
}

Pose BulletSimulation::pose(int body) const {
  return from_bt((*impl_->bodies)[body].getCenterOfMassTransform());
}

Vec3 BulletSimulation::linear_velocity(int body) const {
  return from_bt((*impl_->bodies)[body].getLinearVelocity());
}

Vec3 BulletSimulation::angular_velocity(int body) const {
  return from_bt((*impl_->bodies)[body].getAngularVelocity());
}

Trajectory BulletSimulation::record() {
  const SceneSpec& spec = impl_->spec;
  Trajectory trajectory;
  trajectory.floor = spec.floor;
  trajectory.gravity = spec.gravity;
  trajectory.time_step = spec.frame_step();
  trajectory.seed = spec.seed;
  for (const BodySpec& body : spec.bodies) {
    TrajectoryObject object;
    object.mesh = body.mesh;
    object.properties = body.properties;
    object.kinematic = body.kinematic;
    if (!body.kinematic) object.inertia = body.inertia;
    trajectory.objects.push_back(std::move(object));
  }
  for (int frame = 0; frame < spec.frames; ++frame) {
    if (frame > 0) step_frame();
    for (size_t i = 0; i < spec.bodies.size(); ++i) {
      TrajectoryObject& object = trajectory.objects[i];
      object.poses.push_back(pose(static_cast<int>(i)));
      object.linear_velocities.push_back(linear_velocity(static_cast<int>(i)));
      object.angular_velocities.push_back(angular_velocity(static_cast<int>(i)));
    }
  }
  return trajectory;
}

}  // namespace fignet::bullet
