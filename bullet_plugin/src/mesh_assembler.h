// Builds a TriangleMesh from loose triangles (mesh files, hulls, triangles of static meshes,
// compound children): points welded by exact position, collapsed faces skipped, unused vertices
// dropped, numbered in order of first use.
#pragma once

#include <LinearMath/btTransform.h>

#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "fignet/geometry/mesh.h"

namespace fignet::bullet {

class MeshAssembler {
 public:
  // Adds a triangle unless welding collapses it (two corners at the same point).
  void triangle(const Vec3& a, const Vec3& b, const Vec3& c);
  // Appends `mesh` moved by `transform`, its vertices kept apart from the others (compound
  // children may touch without sharing a surface).
  void append(const TriangleMesh& mesh, const btTransform& transform);
  // The same in double precision (a btTransform is float in Debian's Bullet).
  void append(const TriangleMesh& mesh, const Eigen::Isometry3d& transform);
  bool empty() const { return faces_.empty(); }
  // The mesh, zero-area faces dropped. Throws MeshError as TriangleMesh does.
  TriangleMesh finish(std::string name) const;

 private:
  int vertex(const Vec3& p);
  void append(const TriangleMesh& mesh, const std::function<Vec3(const Vec3&)>& move);

  std::map<std::array<double, 3>, int> index_;
  std::vector<Vec3> points_;
  std::vector<std::array<int, 3>> faces_;
};

// The convex hull of `points` as a closed, outward-facing mesh (each hull face fanned from its
// first vertex); empty when the points are flat or fewer than four.
MeshAssembler convex_hull_triangles(const Points& points);

}  // namespace fignet::bullet
