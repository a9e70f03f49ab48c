#include "fignet/geometry/mesh.h"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "fignet/error.h"

namespace fignet {

Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3::Zero();
}

namespace {

void check_vertices(const std::string& name, const Points& vertices) {
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    if (!vertices.row(i).allFinite()) {
      throw MeshError(fmt::format("mesh '{}': vertex {} is not finite ({}, {}, {})", name, i,
                                  vertices(i, 0), vertices(i, 1), vertices(i, 2)));
    }
  }
}

void check_indices(const std::string& name, const Triangles& faces, Eigen::Index num_vertices) {
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const auto index = faces(f, k);
      if (index < 0 || index >= num_vertices) {
        throw MeshError(fmt::format("mesh '{}': face {} references vertex {}, but the mesh has {}",
                                    name, f, index, num_vertices));
      }
    }
    if (faces(f, 0) == faces(f, 1) || faces(f, 1) == faces(f, 2) || faces(f, 0) == faces(f, 2)) {
      throw MeshError(fmt::format("mesh '{}': face {} repeats a vertex ({}, {}, {})", name, f,
                                  faces(f, 0), faces(f, 1), faces(f, 2)));
    }
  }
}

// Removes (or rejects) faces whose area is negligible relative to the mesh's size.
Triangles filter_degenerate(const std::string& name, const Points& vertices, const Triangles& faces,
                            const MeshOptions& options, int* dropped) {
  const double diagonal = (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
  const double min_area = options.degenerate_area_ratio * diagonal * diagonal;
  std::vector<Eigen::Index> kept;
  kept.reserve(faces.rows());
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Vec3 a = vertices.row(faces(f, 0)), b = vertices.row(faces(f, 1)),
               c = vertices.row(faces(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (area > min_area) {
      kept.push_back(f);
    } else if (options.degenerate_faces == DegenerateFaces::kReject) {
      throw MeshError(
          fmt::format("mesh '{}': face {} is degenerate (area {:.3g} <= {:.3g}); pass "
                      "DegenerateFaces::kDrop to remove such faces",
                      name, f, area, min_area));
    }
  }
  *dropped = static_cast<int>(faces.rows() - static_cast<Eigen::Index>(kept.size()));
  Triangles result(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t i = 0; i < kept.size(); ++i) result.row(i) = faces.row(kept[i]);
  return result;
}

EdgeList unique_edges(const Triangles& faces) {
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;
  edges.reserve(3 * faces.rows());
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const auto a = faces(f, k), b = faces(f, (k + 1) % 3);
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  EdgeList result(static_cast<Eigen::Index>(edges.size()), 2);
  for (size_t i = 0; i < edges.size(); ++i) result.row(i) << edges[i].first, edges[i].second;
  return result;
}

}  // namespace

TriangleMesh::TriangleMesh(std::string name, Points vertices, Triangles faces,
                           const MeshOptions& options)
    : name_(std::move(name)), vertices_(std::move(vertices)) {
  if (faces.rows() == 0) throw MeshError(fmt::format("mesh '{}': has no faces", name_));
  check_vertices(name_, vertices_);
  check_indices(name_, faces, vertices_.rows());
  faces_ = filter_degenerate(name_, vertices_, faces, options, &dropped_faces_);
  if (faces_.rows() == 0) {
    throw MeshError(fmt::format("mesh '{}': all {} faces are degenerate", name_, faces.rows()));
  }
  edges_ = unique_edges(faces_);
  face_normals_.resize(faces_.rows(), 3);
  for (Eigen::Index f = 0; f < faces_.rows(); ++f) {
    face_normals_.row(f) = triangle_normal(vertices_.row(faces_(f, 0)), vertices_.row(faces_(f, 1)),
                                           vertices_.row(faces_(f, 2)));
  }
}

TriangleMesh mesh_of_used_vertices(std::string name, const Points& vertices,
                                   std::span<const std::array<int, 3>> faces) {
  // Every vertex becomes a graph node: keep only those the faces use.
  std::vector<int> renumber(static_cast<size_t>(vertices.rows()), -1);
  int used = 0;
  for (const auto& face : faces)
    for (int v : face)
      if (renumber[static_cast<size_t>(v)] < 0) renumber[static_cast<size_t>(v)] = used++;
  Points kept(used, 3);
  for (Eigen::Index v = 0; v < vertices.rows(); ++v)
    if (renumber[static_cast<size_t>(v)] >= 0)
      kept.row(renumber[static_cast<size_t>(v)]) = vertices.row(v);
  Triangles triangles(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) {
    triangles.row(static_cast<Eigen::Index>(f)) << renumber[static_cast<size_t>(faces[f][0])],
        renumber[static_cast<size_t>(faces[f][1])], renumber[static_cast<size_t>(faces[f][2])];
  }
  MeshOptions options;
  options.degenerate_faces = DegenerateFaces::kDrop;
  return TriangleMesh(std::move(name), std::move(kept), std::move(triangles), options);
}

TriangleMesh mirrored_mesh(const TriangleMesh& mesh) {
  Points vertices = mesh.vertices();
  vertices.col(1) = -vertices.col(1);
  // A reflection turns right-handed windings left-handed: swapping two corners turns them back.
  Triangles faces = mesh.faces();
  faces.col(1).swap(faces.col(2));
  return TriangleMesh(mesh.name() + " (mirrored)", std::move(vertices), std::move(faces));
}

bool TriangleMesh::is_closed() const {
  // Each directed half-edge must appear once, and its twin (reversed) exactly once.
  std::map<std::pair<std::int32_t, std::int32_t>, int> half_edges;
  for (Eigen::Index f = 0; f < faces_.rows(); ++f) {
    for (int k = 0; k < 3; ++k) ++half_edges[{faces_(f, k), faces_(f, (k + 1) % 3)}];
  }
  for (const auto& [edge, count] : half_edges) {
    if (count != 1) return false;
    const auto twin = half_edges.find({edge.second, edge.first});
    if (twin == half_edges.end() || twin->second != 1) return false;
  }
  return true;
}

}  // namespace fignet
