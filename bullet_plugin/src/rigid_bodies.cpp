#include "fignet/bullet/rigid_bodies.h"

#include <btBulletDynamicsCommon.h>

#include <string>

#include "fignet/bullet/conversions.h"
#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/error.h"

namespace fignet::bullet {

namespace {

std::unique_ptr<btConvexHullShape> make_hull(const Points& points, double margin) {
  auto hull = std::make_unique<btConvexHullShape>();
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    hull->addPoint(to_bt(Vec3(points.row(v).transpose())), false);
  }
  hull->recalcLocalAabb();
  hull->setMargin(btScalar(margin));
  return hull;
}

}  // namespace

RigidBodies::RigidBodies(btDiscreteDynamicsWorld& world) : world_(world) {}

RigidBodies::~RigidBodies() {
  // The world must let go of the bodies before they are destroyed.
  for (auto& body : bodies_) world_.removeRigidBody(body.get());
}

std::unique_ptr<btCollisionShape> RigidBodies::make_shape(const BodySpec& spec, double margin) {
  if (spec.convex_parts.empty()) return make_hull(spec.mesh->vertices(), margin);
  if (spec.convex_parts.size() == 1) return make_hull(spec.convex_parts.front(), margin);
  auto compound = std::make_unique<btCompoundShape>();
  for (const Points& part : spec.convex_parts) {
    shapes_.push_back(make_hull(part, margin));
    compound->addChildShape(btTransform::getIdentity(), shapes_.back().get());
  }
  return compound;
}

btRigidBody* RigidBodies::add(std::unique_ptr<btCollisionShape> shape, double mass,
                              const btVector3& inertia, const btTransform& transform) {
  motion_states_.push_back(std::make_unique<btDefaultMotionState>(transform));
  const btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), motion_states_.back().get(),
                                                      shape.get(), inertia);
  bodies_.push_back(std::make_unique<btRigidBody>(info));
  shapes_.push_back(std::move(shape));
  world_.addRigidBody(bodies_.back().get());
  return bodies_.back().get();
}

btRigidBody* RigidBodies::add(const BodySpec& spec, double collision_margin) {
  const std::string name = spec.mesh ? spec.mesh->name() : "";
  if (!spec.mesh) throw ConfigError("bullet body " + std::to_string(size()) + ": no mesh");
  if (!spec.kinematic && !(spec.properties.mass > 0.0)) {
    throw ConfigError("bullet body '" + name + "': a dynamic body needs a positive mass");
  }
  const double mass = spec.kinematic ? 0.0 : spec.properties.mass;
  btRigidBody* body =
      add(make_shape(spec, collision_margin), mass,
          spec.kinematic ? btVector3(0, 0, 0) : to_bt(spec.inertia), to_bt(spec.pose));
  // A FIGNet world sees the spec's mesh, not the hull's triangulation of it.
  if (auto* fignet_world = dynamic_cast<FIGNetDynamicsWorld*>(&world_)) {
    fignet_world->set_shape_mesh(*body->getCollisionShape(), spec.mesh);
  }
  body->setFriction(btScalar(spec.properties.friction));
  body->setRestitution(btScalar(spec.properties.restitution));
  if (spec.kinematic) {
    body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    body->setActivationState(DISABLE_DEACTIVATION);  // Bullet's rule for kinematic bodies
  } else {
    body->setLinearVelocity(to_bt(spec.linear_velocity));
    body->setAngularVelocity(to_bt(spec.angular_velocity));
  }
  return body;
}

}  // namespace fignet::bullet
