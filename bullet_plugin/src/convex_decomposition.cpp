#include "fignet/bullet/convex_decomposition.h"

#include <HACD/hacdHACD.h>
#include <fmt/format.h>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "mesh_assembler.h"

namespace fignet::bullet {

double convex_hull_volume(const Points& points) {
  const MeshAssembler hull = convex_hull_triangles(points);
  return hull.empty() ? 0.0 : compute_mass_properties(hull.finish("convex hull")).volume;
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

std::vector<Points> collision_parts(const TriangleMesh& mesh, bool* hacd_failed,
                                    const ConvexDecompositionOptions& options) {
  if (hacd_failed) *hacd_failed = false;
  std::vector<Points> parts = decompose_into_convex_parts(mesh, options);
  if (parts.empty()) return parts;  // convex: one hull is exact
  double covered = 0.0;
  for (const Points& part : parts) {
    try {
      covered += convex_hull_volume(part);
    } catch (const MeshError&) {  // a flat sliver covers nothing
    }
  }
  if (parts.size() <= 256 && covered >= 0.5 * compute_mass_properties(mesh).volume) return parts;
  if (hacd_failed) *hacd_failed = true;
  return {};
}

}  // namespace fignet::bullet
