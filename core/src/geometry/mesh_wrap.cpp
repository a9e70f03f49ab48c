// wrap_mesh(): CGAL's 3D alpha wrapping, alone in this file because CGAL's templates are slow to
// compile; a build without CGAL (FIGNET_WITH_CGAL off) says so when asked to wrap.
#include <fmt/format.h>

#include <array>
#include <vector>

#include "fignet/error.h"
#include "fignet/geometry/mesh_repair.h"

#ifdef FIGNET_WITH_CGAL
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>
#endif

namespace fignet {

bool mesh_wrapping_available() {
#ifdef FIGNET_WITH_CGAL
  return true;
#else
  return false;
#endif
}

TriangleMesh wrap_mesh(const TriangleMesh& mesh, const WrapOptions& options) {
  if (!(options.relative_alpha > 0.0) || !(options.relative_offset > 0.0)) {
    throw ConfigError(fmt::format("mesh '{}': wrap alpha {} and offset {} (both must be > 0)",
                                  mesh.name(), options.relative_alpha, options.relative_offset));
  }
#ifdef FIGNET_WITH_CGAL
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = Kernel::Point_3;
  // About the box centre: CGAL's offset and alpha are absolute, the input may be far out.
  const Vec3 centre =
      0.5 * (mesh.vertices().colwise().maxCoeff() + mesh.vertices().colwise().minCoeff());
  std::vector<Point> points;
  points.reserve(static_cast<size_t>(mesh.num_vertices()));
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3 p = mesh.vertices().row(v).transpose() - centre;
    points.emplace_back(p.x(), p.y(), p.z());
  }
  std::vector<std::array<size_t, 3>> faces;
  faces.reserve(static_cast<size_t>(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    faces.push_back({static_cast<size_t>(mesh.faces()(f, 0)),
                     static_cast<size_t>(mesh.faces()(f, 1)),
                     static_cast<size_t>(mesh.faces()(f, 2))});
  }
  const double diagonal =
      (mesh.vertices().colwise().maxCoeff() - mesh.vertices().colwise().minCoeff()).norm();
  CGAL::Surface_mesh<Point> wrap;
  CGAL::alpha_wrap_3(points, faces, options.relative_alpha * diagonal,
                     options.relative_offset * diagonal, wrap);
  if (wrap.number_of_faces() == 0) {
    throw MeshError(fmt::format("mesh '{}': alpha wrapping produced no surface", mesh.name()));
  }

  // Surface_mesh indices may have gaps after removals: number the vertices afresh.
  std::vector<int> index(wrap.num_vertices(), -1);
  Points vertices(static_cast<Eigen::Index>(wrap.number_of_vertices()), 3);
  int next = 0;
  for (const auto v : wrap.vertices()) {
    const Point& p = wrap.point(v);
    vertices.row(next) << p.x() + centre.x(), p.y() + centre.y(), p.z() + centre.z();
    index[v.idx()] = next++;
  }
  Triangles triangles(static_cast<Eigen::Index>(wrap.number_of_faces()), 3);
  Eigen::Index row = 0;
  for (const auto f : wrap.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(wrap.halfedge(f), wrap)) {
      if (k < 3) triangles(row, k) = index[v.idx()];
      ++k;
    }
    if (k != 3) {
      throw MeshError(fmt::format("mesh '{}': alpha wrap face with {} corners", mesh.name(), k));
    }
    ++row;
  }
  MeshOptions mesh_options;
  mesh_options.degenerate_faces = DegenerateFaces::kDrop;
  return TriangleMesh(mesh.name(), std::move(vertices), std::move(triangles), mesh_options);
#else
  throw ConfigError(
      fmt::format("mesh '{}': wrapping an open mesh needs CGAL, and this build has none (install "
                  "libcgal-dev and reconfigure with FIGNET_WITH_CGAL=ON)",
                  mesh.name()));
#endif
}

}  // namespace fignet
