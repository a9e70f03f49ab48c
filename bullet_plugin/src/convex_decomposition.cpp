#include "fignet/bullet/convex_decomposition.h"

#include <HACD/hacdHACD.h>
#include <LinearMath/btConvexHullComputer.h>
#include <fmt/format.h>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"

namespace fignet::bullet {

double convex_hull_volume(const Points& points) {
  btConvexHullComputer hull;
  hull.compute(points.data(), sizeof(double) * 3, static_cast<int>(points.rows()), 0.0, 0.0);
  // Sum of tetrahedra from the first hull vertex over every (fan-triangulated) hull face.
  double volume = 0.0;
  if (hull.vertices.size() < 4) return 0.0;
  const btVector3 origin = hull.vertices[0];
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const btVector3 a = hull.vertices[first->getSourceVertex()];
    const btConvexHullComputer::Edge* edge = first->getNextEdgeOfFace();
    for (; edge->getTargetVertex() != first->getSourceVertex(); edge = edge->getNextEdgeOfFace()) {
      const btVector3 b = hull.vertices[edge->getSourceVertex()];
      const btVector3 c = hull.vertices[edge->getTargetVertex()];
      volume += (a - origin).dot((b - origin).cross(c - origin)) / 6.0;
    }
  }
  return std::abs(volume);
}

std::vector<Points> decompose_into_convex_parts(const TriangleMesh& mesh,
                                                const ConvexDecompositionOptions& options) {
  const double volume = compute_mass_properties(mesh).volume;
  if (convex_hull_volume(mesh.vertices()) <= volume * (1.0 + options.convexity_tolerance)) {
    return {};
  }
  std::vector<HACD::Vec3<HACD::Real>> points;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    points.emplace_back(mesh.vertices()(v, 0), mesh.vertices()(v, 1), mesh.vertices()(v, 2));
  }
  std::vector<HACD::Vec3<long>> triangles;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    triangles.emplace_back(mesh.faces()(f, 0), mesh.faces()(f, 1), mesh.faces()(f, 2));
  }
  const Vec3 extent = mesh.vertices().colwise().maxCoeff() - mesh.vertices().colwise().minCoeff();
  HACD::HACD hacd;
  hacd.SetPoints(points.data());
  hacd.SetNPoints(points.size());
  hacd.SetTriangles(triangles.data());
  hacd.SetNTriangles(triangles.size());
  hacd.SetCompacityWeight(0.1);
  hacd.SetVolumeWeight(0.0);
  hacd.SetNClusters(options.min_parts);
  hacd.SetNVerticesPerCH(options.max_vertices_per_hull);
  hacd.SetConcavity(options.concavity * extent.norm());
  hacd.SetAddExtraDistPoints(true);
  hacd.SetAddNeighboursDistPoints(true);
  hacd.SetAddFacesPoints(true);
  if (!hacd.Compute()) {
    throw MeshError(fmt::format("mesh '{}': HACD convex decomposition failed", mesh.name()));
  }
  std::vector<Points> parts;
  for (size_t c = 0; c < hacd.GetNClusters(); ++c) {
    std::vector<HACD::Vec3<HACD::Real>> hull_points(hacd.GetNPointsCH(c));
    std::vector<HACD::Vec3<long>> hull_triangles(hacd.GetNTrianglesCH(c));
    hacd.GetCH(c, hull_points.data(), hull_triangles.data());
    Points part(static_cast<Eigen::Index>(hull_points.size()), 3);
    for (size_t i = 0; i < hull_points.size(); ++i) {
      part.row(static_cast<Eigen::Index>(i)) << hull_points[i].X(), hull_points[i].Y(),
          hull_points[i].Z();
    }
    parts.push_back(std::move(part));
  }
  if (parts.empty()) {
    throw MeshError(fmt::format("mesh '{}': HACD returned no convex parts", mesh.name()));
  }
  return parts;
}

}  // namespace fignet::bullet
