#include "fignet/geometry/mesh_repair.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>
#include <vector>

#include "fignet/error.h"

namespace fignet {

bool MeshDefects::clean() const {
  return closed() && welded_vertices == 0 && degenerate_faces == 0 && duplicate_faces == 0 &&
         flipped_faces == 0 && inverted_shells == 0;
}

std::string MeshDefects::summary() const {
  std::vector<std::string> parts;
  const auto add = [&](int count, const char* one, const char* many) {
    if (count > 0) parts.push_back(fmt::format("{} {}", count, count == 1 ? one : many));
  };
  add(shells > 1 ? shells : 0, "shell", "shells");
  add(boundary_edges, "open edge", "open edges");
  add(non_manifold_edges, "non-manifold edge", "non-manifold edges");
  if (non_orientable) parts.push_back("not orientable");
  add(welded_vertices, "coincident vertex welded", "coincident vertices welded");
  add(degenerate_faces, "degenerate face dropped", "degenerate faces dropped");
  add(duplicate_faces, "repeated face dropped", "repeated faces dropped");
  add(flipped_faces, "face flipped", "faces flipped");
  add(inverted_shells, "shell turned outward", "shells turned outward");
  return parts.empty() ? "clean" : fmt::format("{}", fmt::join(parts, ", "));
}

namespace {

// Union-find over face indices (shells are the faces connected through shared edges).
class Components {
 public:
  explicit Components(int n) : parent_(static_cast<size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void join(int a, int b) { parent_[find(a)] = find(b); }

 private:
  std::vector<int> parent_;
};

// Maps each vertex to the first earlier vertex within `tolerance` (grid of that cell size, the 27
// neighbouring cells searched). Returns the number of vertices merged.
int weld(const Points& vertices, double tolerance, std::vector<int>& target) {
  const Eigen::Index n = vertices.rows();
  target.resize(static_cast<size_t>(n));
  std::iota(target.begin(), target.end(), 0);
  if (!(tolerance > 0.0)) return 0;
  struct CellHash {
    size_t operator()(const std::array<long long, 3>& c) const {
      return static_cast<size_t>(c[0] * 73856093LL ^ c[1] * 19349663LL ^ c[2] * 83492791LL);
    }
  };
  std::unordered_map<std::array<long long, 3>, std::vector<int>, CellHash> grid;
  // Cells counted from the box's corner: at most diagonal / tolerance of them along an axis.
  const Vec3 corner = vertices.colwise().minCoeff().transpose();
  int merged = 0;
  for (Eigen::Index v = 0; v < n; ++v) {
    const Vec3 p = vertices.row(v).transpose();
    std::array<long long, 3> cell;
    for (int k = 0; k < 3; ++k)
      cell[k] = static_cast<long long>(std::floor((p[k] - corner[k]) / tolerance));
    int found = -1;
    for (long long dx = -1; dx <= 1 && found < 0; ++dx)
      for (long long dy = -1; dy <= 1 && found < 0; ++dy)
        for (long long dz = -1; dz <= 1 && found < 0; ++dz) {
          const auto it = grid.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == grid.end()) continue;
          for (int other : it->second) {
            if ((vertices.row(other).transpose() - p).norm() <= tolerance) {
              found = other;
              break;
            }
          }
        }
    if (found >= 0) {
      target[static_cast<size_t>(v)] = found;
      ++merged;
    } else {
      grid[cell].push_back(static_cast<int>(v));
    }
  }
  return merged;
}

using Face = std::array<int, 3>;

// Signed volume enclosed by `faces` (listed in `members`), taken about `origin`, times 6.
double signed_volume6(const Points& vertices, const std::vector<Face>& faces,
                      const std::vector<int>& members, const Vec3& origin) {
  double sum = 0.0;
  for (int f : members) {
    const Vec3 a = vertices.row(faces[f][0]).transpose() - origin;
    const Vec3 b = vertices.row(faces[f][1]).transpose() - origin;
    const Vec3 c = vertices.row(faces[f][2]).transpose() - origin;
    sum += a.dot(b.cross(c));
  }
  return sum;
}

}  // namespace

CleanedMesh clean_mesh(std::string name, const Points& vertices, const Triangles& faces,
                       const CleanMeshOptions& options) {
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    if (!vertices.row(v).allFinite()) {
      throw MeshError(fmt::format("mesh '{}': vertex {} is not finite", name, v));
    }
  }
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (faces(f, k) < 0 || faces(f, k) >= vertices.rows()) {
        throw MeshError(fmt::format("mesh '{}': face {} references vertex {}, but the mesh has {}",
                                    name, f, faces(f, k), vertices.rows()));
      }
    }
  }
  if (faces.rows() == 0) throw MeshError(fmt::format("mesh '{}': has no faces", name));
  MeshDefects defects;
  const double diagonal = (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();

  // Weld, then drop faces that collapse, have negligible area, or repeat an earlier face.
  std::vector<int> target;
  defects.welded_vertices = weld(vertices, options.weld_tolerance * diagonal, target);
  const double min_area = 1e-12 * diagonal * diagonal;
  std::vector<Face> kept;
  std::map<Face, int> seen;  // sorted corners → first face
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    Face face;
    for (int k = 0; k < 3; ++k) face[k] = target[static_cast<size_t>(faces(f, k))];
    const Vec3 a = vertices.row(face[0]), b = vertices.row(face[1]), c = vertices.row(face[2]);
    if (face[0] == face[1] || face[1] == face[2] || face[0] == face[2] ||
        0.5 * (b - a).cross(c - a).norm() <= min_area) {
      ++defects.degenerate_faces;
      continue;
    }
    Face sorted = face;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.emplace(sorted, static_cast<int>(kept.size())).second) {
      ++defects.duplicate_faces;
      continue;
    }
    kept.push_back(face);
  }
  if (kept.empty()) {
    throw MeshError(fmt::format("mesh '{}': all {} faces are degenerate", name, faces.rows()));
  }
  const int face_count = static_cast<int>(kept.size());

  // Undirected edges → the faces on them, and each face's direction along them (+1: a→b, a<b).
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> edge_faces;
  for (int f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = kept[f][k], b = kept[f][(k + 1) % 3];
      edge_faces[{std::min(a, b), std::max(a, b)}].emplace_back(f, a < b ? 1 : -1);
    }
  }
  Components shells(face_count);
  for (const auto& [edge, on] : edge_faces) {
    if (on.size() == 1) ++defects.boundary_edges;
    if (on.size() > 2) ++defects.non_manifold_edges;
    for (size_t i = 1; i < on.size(); ++i) shells.join(on[0].first, on[i].first);
  }

  // Wind each shell consistently: breadth-first across manifold edges, a neighbour must run the
  // shared edge the other way. flip[f] says whether face f is reversed.
  std::vector<std::vector<std::pair<int, int>>> neighbours(static_cast<size_t>(face_count));
  for (const auto& [edge, on] : edge_faces) {
    if (on.size() != 2) continue;
    // Same direction on the shared edge: the two faces disagree (one must flip).
    const int disagree = on[0].second == on[1].second ? 1 : 0;
    neighbours[on[0].first].emplace_back(on[1].first, disagree);
    neighbours[on[1].first].emplace_back(on[0].first, disagree);
  }
  std::vector<int> flip(static_cast<size_t>(face_count), -1);
  std::map<int, std::vector<int>> members;  // shell root → faces
  for (int start = 0; start < face_count; ++start) {
    if (flip[start] >= 0) continue;
    std::vector<int> region = {start};
    flip[start] = 0;
    for (size_t i = 0; i < region.size(); ++i) {
      const int f = region[i];
      for (const auto& [g, disagree] : neighbours[f]) {
        const int wanted = flip[f] ^ disagree;
        if (flip[g] < 0) {
          flip[g] = wanted;
          region.push_back(g);
        } else if (flip[g] != wanted) {
          defects.non_orientable = true;
        }
      }
    }
    // The majority's winding is the intended one.
    const auto flipped =
        std::count_if(region.begin(), region.end(), [&](int f) { return flip[f]; });
    if (2 * flipped > static_cast<long>(region.size())) {
      for (int f : region) flip[f] ^= 1;
    }
    for (int f : region) members[shells.find(f)].push_back(f);
  }
  for (int f = 0; f < face_count; ++f) {
    if (flip[f]) {
      std::swap(kept[f][1], kept[f][2]);
      ++defects.flipped_faces;
    }
  }
  defects.shells = static_cast<int>(members.size());

  // Outward: a shell enclosing negative volume about its own centroid is turned over.
  for (const auto& [root, shell] : members) {
    Vec3 centroid = Vec3::Zero();
    for (int f : shell)
      for (int v : kept[f]) centroid += vertices.row(v).transpose();
    centroid /= 3.0 * static_cast<double>(shell.size());
    if (signed_volume6(vertices, kept, shell, centroid) < 0.0) {
      for (int f : shell) std::swap(kept[f][1], kept[f][2]);
      ++defects.inverted_shells;
    }
  }

  return {mesh_of_used_vertices(std::move(name), vertices, kept), defects};
}

}  // namespace fignet
