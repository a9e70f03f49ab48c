#include "fignet/geometry/triangle_distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace fignet {

ClosestPoints closest_points_segments(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                      const Vec3& q1) {
  // Minimise |p0 + s·d1 − (q0 + t·d2)|² over s, t ∈ [0, 1], clamping one parameter at a time.
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double kTiny = 1e-300;
  double s = 0.0, t = 0.0;
  if (a <= kTiny && e <= kTiny) {
    // Both segments are points.
  } else if (a <= kTiny) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kTiny) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      // Parallel segments (denom ≈ 0): any s works; start from s = 0 and let the clamps decide.
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  ClosestPoints result{p0 + s * d1, q0 + t * d2, 0.0};
  result.distance = (result.on_first - result.on_second).norm();
  return result;
}

namespace {

// Closest point on the boundary of t: used when t has no area (its interior is not 2D).
Vec3 closest_point_on_edges(const Vec3& p, const Triangle& t) {
  Vec3 best = t.v[0];
  double best_distance = INFINITY;
  for (int k = 0; k < 3; ++k) {
    const ClosestPoints cp = closest_points_segments(p, p, t.v[k], t.v[(k + 1) % 3]);
    if (cp.distance < best_distance) best_distance = cp.distance, best = cp.on_second;
  }
  return best;
}

}  // namespace

Vec3 closest_point_on_triangle(const Vec3& p, const Triangle& t) {
  // Voronoi-region walk: vertex regions, then edge regions, then the face interior.
  const Vec3 &a = t.v[0], &b = t.v[1], &c = t.v[2];
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;

  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) return a + (d1 / (d1 - d3)) * ab;

  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) return a + (d2 / (d2 - d6)) * ac;

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }

  const double denom = va + vb + vc;
  if (!(denom > 0.0)) return closest_point_on_edges(p, t);  // zero-area triangle
  const double v = vb / denom, w = vc / denom;
  return a + v * ab + w * ac;
}

namespace {

void keep_if_closer(const Vec3& on_a, const Vec3& on_b, ClosestPoints* best) {
  const double distance = (on_a - on_b).norm();
  if (distance < best->distance) *best = {on_a, on_b, distance};
}

// Where segment [p, q] crosses the plane of t: the crossing point and its closest point on t.
// This catches intersections through a face interior, which no vertex or edge pair reveals.
// Crossings inside t are points of the intersection; they are also collected in `inside`.
// Each of the six edges crosses the other triangle at most once.
struct Crossings {
  std::array<Vec3, 6> points;
  int count = 0;
};

void check_edge_crossing(const Vec3& p, const Vec3& q, const Triangle& t, bool edge_on_first,
                         ClosestPoints* best, Crossings* inside) {
  const Vec3 normal = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
  const double dp = normal.dot(p - t.v[0]), dq = normal.dot(q - t.v[0]);
  if (dp * dq > 0.0 || dp == dq) return;  // same side, or the segment lies in the plane
  const Vec3 crossing = p + (dp / (dp - dq)) * (q - p);
  Vec3 on_t = closest_point_on_triangle(crossing, t);
  // A crossing inside the face is an intersection; rounding must not turn it into 1e-17 m.
  const double scale =
      std::max({(t.v[1] - t.v[0]).norm(), (t.v[2] - t.v[0]).norm(), (q - p).norm()});
  if ((crossing - on_t).norm() <= 1e-12 * scale) {
    on_t = crossing;
    inside->points[inside->count++] = crossing;
  }
  if (edge_on_first) {
    keep_if_closer(crossing, on_t, best);
  } else {
    keep_if_closer(on_t, crossing, best);
  }
}

// The midpoint of the two crossings farthest apart: the middle of the intersection segment.
Vec3 intersection_midpoint(const Crossings& crossings) {
  std::pair<int, int> ends{0, 0};
  double longest = -1.0;
  for (int i = 0; i < crossings.count; ++i) {
    for (int j = i; j < crossings.count; ++j) {
      const double d = (crossings.points[i] - crossings.points[j]).squaredNorm();
      if (d > longest) longest = d, ends = {i, j};
    }
  }
  return 0.5 * (crossings.points[ends.first] + crossings.points[ends.second]);
}

}  // namespace

ClosestPoints closest_points_triangles(const Triangle& a, const Triangle& b) {
  // For disjoint triangles the minimum is attained by a vertex–face or an edge–edge pair; for
  // intersecting ones, by an edge crossing the other face (or, if coplanar, by an edge–edge or
  // vertex–face pair at distance 0). Every candidate is a valid pair of points, so the minimum
  // over all of them is exact.
  ClosestPoints best{a.v[0], b.v[0], INFINITY};
  Crossings crossings;
  for (int i = 0; i < 3; ++i) {
    keep_if_closer(a.v[i], closest_point_on_triangle(a.v[i], b), &best);
    keep_if_closer(closest_point_on_triangle(b.v[i], a), b.v[i], &best);
  }
  for (int i = 0; i < 3; ++i) {
    const Vec3 &a0 = a.v[i], &a1 = a.v[(i + 1) % 3];
    for (int j = 0; j < 3; ++j) {
      const ClosestPoints cp = closest_points_segments(a0, a1, b.v[j], b.v[(j + 1) % 3]);
      if (cp.distance < best.distance) best = cp;
    }
    check_edge_crossing(a0, a1, b, /*edge_on_first=*/true, &best, &crossings);
    check_edge_crossing(b.v[i], b.v[(i + 1) % 3], a, /*edge_on_first=*/false, &best, &crossings);
  }
  // Crossing triangles meet along a segment, and any point of it is a closest point. Report its
  // midpoint: it depends on the geometry alone, not on the order of vertices or triangles, which
  // keeps face-face features permutation-equivariant for interpenetrating objects.
  if (crossings.count > 0) {
    const Vec3 middle = intersection_midpoint(crossings);
    return {middle, middle, 0.0};
  }
  // A touching point lies on both triangles: report it once, as the same point.
  if (best.distance == 0.0) best.on_second = best.on_first;
  return best;
}

}  // namespace fignet
