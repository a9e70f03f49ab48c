// Axis-aligned bounding boxes.
#pragma once

#include <algorithm>

#include "fignet/geometry/types.h"

namespace fignet {

struct Aabb {
  Vec3 min = Vec3::Constant(INFINITY);
  Vec3 max = Vec3::Constant(-INFINITY);

  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void extend(const Aabb& other) {
    min = min.cwiseMin(other.min);
    max = max.cwiseMax(other.max);
  }
  Vec3 center() const { return 0.5 * (min + max); }
  Vec3 extent() const { return max - min; }
};

// Squared Euclidean distance between two boxes (0 when they overlap).
inline double squared_distance(const Aabb& a, const Aabb& b) {
  const Vec3 gap = (a.min - b.max).cwiseMax(b.min - a.max).cwiseMax(0.0);
  return gap.squaredNorm();
}

}  // namespace fignet
