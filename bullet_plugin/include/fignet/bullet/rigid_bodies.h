// Bullet rigid bodies built from BodySpecs (mesh files, URDF links, generated scenes), owned
// together with their shapes and motion states, in a world of the caller's choice: a
// btDiscreteDynamicsWorld or a FIGNetDynamicsWorld alike.
#pragma once

#include <memory>
#include <vector>

#include "fignet/bullet/scene_spec.h"

class btCollisionShape;
class btDefaultMotionState;
class btDiscreteDynamicsWorld;
class btRigidBody;
class btTransform;
class btVector3;

namespace fignet::bullet {

class RigidBodies {
 public:
  // Bodies go into `world`, which must outlive this object; they leave it on destruction.
  explicit RigidBodies(btDiscreteDynamicsWorld& world);
  ~RigidBodies();
  RigidBodies(const RigidBodies&) = delete;
  RigidBodies& operator=(const RigidBodies&) = delete;

  // A body of `spec`: the convex hull of its mesh, or a compound of the hulls of its convex
  // parts, with `collision_margin` metres around them; mass, inertia, friction, restitution,
  // pose and velocities from the spec; kinematic specs become CF_KINEMATIC_OBJECT bodies.
  btRigidBody* add(const BodySpec& spec, double collision_margin = 0.005);
  // Any shape, owned from now on (a static plane, for example); mass 0 makes it static.
  btRigidBody* add(std::unique_ptr<btCollisionShape> shape, double mass, const btVector3& inertia,
                   const btTransform& transform);

  int size() const { return static_cast<int>(bodies_.size()); }
  btRigidBody& operator[](int index) { return *bodies_[static_cast<size_t>(index)]; }
  const btRigidBody& operator[](int index) const { return *bodies_[static_cast<size_t>(index)]; }

 private:
  std::unique_ptr<btCollisionShape> make_shape(const BodySpec& spec, double margin);

  btDiscreteDynamicsWorld& world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;  // compound children too
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;  // in order of addition
};

}  // namespace fignet::bullet
