// Exact closest points between points, segments and triangles in 3D, in double precision.
// Handles parallel, coplanar, touching, intersecting and degenerate (zero-area) inputs.
#pragma once

#include "fignet/geometry/types.h"

namespace fignet {

struct Triangle {
  Vec3 v[3];
};

struct ClosestPoints {
  Vec3 on_first;   // point on the first primitive
  Vec3 on_second;  // point on the second primitive
  double distance = 0.0;
};

// Closest point to p on triangle t (which may be degenerate).
Vec3 closest_point_on_triangle(const Vec3& p, const Triangle& t);

// Closest points between segments [p0, p1] and [q0, q1] (either may be a single point).
ClosestPoints closest_points_segments(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                      const Vec3& q1);

// Closest points between two triangles. When they cross, the distance is 0 and both points are
// the midpoint of their intersection segment (a choice independent of vertex order).
ClosestPoints closest_points_triangles(const Triangle& a, const Triangle& b);

}  // namespace fignet
