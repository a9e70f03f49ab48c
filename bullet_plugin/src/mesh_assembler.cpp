#include "mesh_assembler.h"

#include <LinearMath/btConvexHullComputer.h>

#include "fignet/bullet/conversions.h"

namespace fignet::bullet {

int MeshAssembler::vertex(const Vec3& p) {
  const auto [it, inserted] =
      index_.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<int>(points_.size()));
  if (inserted) points_.push_back(p);
  return it->second;
}

void MeshAssembler::triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const int i = vertex(a), j = vertex(b), k = vertex(c);
  if (i != j && j != k && i != k) faces_.push_back({i, j, k});
}

void MeshAssembler::append(const TriangleMesh& mesh, const btTransform& transform) {
  append(mesh, [&](const Vec3& p) { return from_bt(transform * to_bt(p)); });
}

void MeshAssembler::append(const TriangleMesh& mesh, const Eigen::Isometry3d& transform) {
  append(mesh, [&](const Vec3& p) { return Vec3(transform * p); });
}

void MeshAssembler::append(const TriangleMesh& mesh, const std::function<Vec3(const Vec3&)>& move) {
  const int base = static_cast<int>(points_.size());
  for (int v = 0; v < mesh.num_vertices(); ++v)
    points_.push_back(move(mesh.vertices().row(v).transpose()));
  for (int f = 0; f < mesh.num_faces(); ++f)
    faces_.push_back(
        {base + mesh.faces()(f, 0), base + mesh.faces()(f, 1), base + mesh.faces()(f, 2)});
}

TriangleMesh MeshAssembler::finish(std::string name) const {
  Points points(static_cast<Eigen::Index>(points_.size()), 3);
  for (size_t v = 0; v < points_.size(); ++v)
    points.row(static_cast<Eigen::Index>(v)) = points_[v].transpose();
  return mesh_of_used_vertices(std::move(name), points, faces_);
}

MeshAssembler convex_hull_triangles(const Points& points) {
  MeshAssembler assembler;
  btConvexHullComputer hull;
  hull.compute(points.data(), sizeof(double) * 3, static_cast<int>(points.rows()), 0.0, 0.0);
  if (hull.vertices.size() < 4) return assembler;
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const Vec3 a = from_bt(hull.vertices[first->getSourceVertex()]);
    for (const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace();
         e->getTargetVertex() != first->getSourceVertex(); e = e->getNextEdgeOfFace()) {
      assembler.triangle(a, from_bt(hull.vertices[e->getSourceVertex()]),
                         from_bt(hull.vertices[e->getTargetVertex()]));
    }
  }
  return assembler;
}

}  // namespace fignet::bullet
