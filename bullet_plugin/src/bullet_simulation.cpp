#include "fignet/bullet/bullet_simulation.h"

#include <btBulletDynamicsCommon.h>

#include "fignet/bullet/conversions.h"
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
  // Compound children are owned here (a compound does not own them).
  std::vector<std::unique_ptr<btCollisionShape>> child_shapes;

  std::unique_ptr<btConvexHullShape> make_hull(const Points& points, double margin) {
    auto hull = std::make_unique<btConvexHullShape>();
    for (Eigen::Index v = 0; v < points.rows(); ++v) {
      hull->addPoint(to_bt(Vec3(points.row(v).transpose())), false);
    }
    hull->recalcLocalAabb();
    hull->setMargin(btScalar(margin));
    return hull;
  }

  // A convex hull of the mesh, or a compound of the hulls of its convex parts.
  std::unique_ptr<btCollisionShape> make_shape(const BodySpec& body, double margin) {
    if (body.convex_parts.empty()) return make_hull(body.mesh->vertices(), margin);
    auto compound = std::make_unique<btCompoundShape>();
    for (const Points& part : body.convex_parts) {
      child_shapes.push_back(make_hull(part, margin));
      compound->addChildShape(btTransform::getIdentity(), child_shapes.back().get());
    }
    return compound;
  }

  SceneSpec spec;
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  std::unique_ptr<btDiscreteDynamicsWorld> world_owner;
  btDiscreteDynamicsWorld* world_ = nullptr;
  int steps_per_frame = 1;
  btDiscreteDynamicsWorld& world() { return *world_; }
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;  // spec order; the floor, if any, last
  long long steps = 0;

  ~Impl() {
    // The world must let go of its bodies before they are destroyed.
    for (auto& body : bodies) world_->removeRigidBody(body.get());
  }

  btRigidBody* add(std::unique_ptr<btCollisionShape> shape, double mass, const btVector3& inertia,
                   const btTransform& transform) {
    motion_states.push_back(std::make_unique<btDefaultMotionState>(transform));
    btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), motion_states.back().get(),
                                                  shape.get(), inertia);
    bodies.push_back(std::make_unique<btRigidBody>(info));
    shapes.push_back(std::move(shape));
    world_->addRigidBody(bodies.back().get());
    return bodies.back().get();
  }
};

BulletSimulation::BulletSimulation(const SceneSpec& spec, const SolverSettings& settings,
                                   const WorldFactory& make_world)
    : impl_(std::make_unique<Impl>()) {
  impl_->spec = spec;
  Impl& impl = *impl_;
  impl.world_owner =
      make_world ? make_world(&impl.dispatcher, &impl.broadphase, &impl.solver, &impl.configuration)
                 : std::make_unique<btDiscreteDynamicsWorld>(&impl.dispatcher, &impl.broadphase,
                                                             &impl.solver, &impl.configuration);
  impl.world_ = impl.world_owner.get();
  impl.steps_per_frame =
      settings.steps_per_frame > 0 ? settings.steps_per_frame : spec.steps_per_frame;
  btDiscreteDynamicsWorld& world = impl.world();
  world.setGravity(to_bt(spec.gravity));
  btContactSolverInfo& info = world.getSolverInfo();
  info.m_numIterations = settings.iterations;
  info.m_splitImpulse = settings.split_impulse;
  if (!settings.warm_starting) info.m_solverMode &= ~SOLVER_USE_WARMSTARTING;
  info.m_restitutionVelocityThreshold = btScalar(settings.restitution_velocity_threshold);
  info.m_linearSlop = btScalar(settings.linear_slop);

  for (size_t i = 0; i < spec.bodies.size(); ++i) {
    const BodySpec& body = spec.bodies[i];
    if (!body.mesh) throw ConfigError("bullet scene: body " + std::to_string(i) + " has no mesh");
    const double mass = body.kinematic ? 0.0 : body.properties.mass;
    btRigidBody* rigid =
        impl_->add(impl_->make_shape(body, spec.collision_margin), mass,
                   body.kinematic ? btVector3(0, 0, 0) : to_bt(body.inertia), to_bt(body.pose));
    rigid->setFriction(btScalar(body.properties.friction));
    rigid->setRestitution(btScalar(body.properties.restitution));
    rigid->setActivationState(DISABLE_DEACTIVATION);  // datasets record every body every frame
    if (body.kinematic) {
      rigid->setCollisionFlags(rigid->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    } else {
      rigid->setLinearVelocity(to_bt(body.linear_velocity));
      rigid->setAngularVelocity(to_bt(body.angular_velocity));
    }
  }
  if (spec.floor) {
    auto plane =
        std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), btScalar(spec.floor->height));
    btRigidBody* floor =
        impl_->add(std::move(plane), 0.0, btVector3(0, 0, 0), btTransform::getIdentity());
    floor->setFriction(btScalar(spec.floor->properties.friction));
    floor->setRestitution(btScalar(spec.floor->properties.restitution));
  }
}

BulletSimulation::~BulletSimulation() = default;

btDiscreteDynamicsWorld& BulletSimulation::world() {
  return impl_->world();
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
      impl_->motion_states[i]->setWorldTransform(
          to_bt(scripted_pose(spec.bodies[i], impl_->steps * step)));
    }
    impl_->world().stepSimulation(btScalar(step), 0, btScalar(step));
  }
}

Pose BulletSimulation::pose(int body) const {
  return from_bt(impl_->bodies[body]->getCenterOfMassTransform());
}

Vec3 BulletSimulation::linear_velocity(int body) const {
  return from_bt(impl_->bodies[body]->getLinearVelocity());
}

Vec3 BulletSimulation::angular_velocity(int body) const {
  return from_bt(impl_->bodies[body]->getAngularVelocity());
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
