// Conversions between Bullet's and Eigen's vectors, transforms and poses.
#pragma once

#include <LinearMath/btTransform.h>

#include "fignet/graph/scene.h"

namespace fignet::bullet {

inline btVector3 to_bt(const Vec3& v) {
  return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z()));
}
inline Vec3 from_bt(const btVector3& v) {
  return Vec3(v.x(), v.y(), v.z());
}

inline btTransform to_bt(const Pose& pose) {
  const Eigen::Quaterniond q = pose.orientation.normalized();
  return btTransform(
      btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
      to_bt(pose.position));
}

inline Pose from_bt(const btTransform& transform) {
  const btQuaternion q = transform.getRotation();
  Pose pose;
  pose.position = from_bt(transform.getOrigin());
  pose.orientation = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized();
  return pose;
}

}  // namespace fignet::bullet
