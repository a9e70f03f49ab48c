// Triangle meshes of rigid objects: rest vertices, faces, and the quantities derived from them
// (unique undirected edges, outward face normals). A TriangleMesh is validated on construction
// and immutable afterwards.
#pragma once

#include <array>
#include <span>
#include <string>

#include "fignet/geometry/types.h"

namespace fignet {

// What to do with faces whose area is (numerically) zero. Their normal is undefined, so a
// face-face edge built on one would carry a meaningless feature.
enum class DegenerateFaces {
  kReject,  // throw MeshError naming the first degenerate face (default)
  kDrop,    // remove them; TriangleMesh::dropped_faces() says how many
};

struct MeshOptions {
  DegenerateFaces degenerate_faces = DegenerateFaces::kReject;
  // A face is degenerate when its area is below this fraction of the squared bounding-box
  // diagonal (scale-free, so millimetre and kilometre meshes are judged alike).
  double degenerate_area_ratio = 1e-12;
};

class TriangleMesh {
 public:
  TriangleMesh() = default;

  // Validates and takes ownership. Throws MeshError naming `name` and the defect when a vertex is
  // NaN/inf, an index is out of range, the mesh has no faces, a face repeats a vertex, or a face is
  // degenerate under `options`.
  TriangleMesh(std::string name, Points vertices, Triangles faces, const MeshOptions& options = {});

  const std::string& name() const { return name_; }
  const Points& vertices() const { return vertices_; }
  const Triangles& faces() const { return faces_; }
  // Unique undirected edges (i < j), sorted lexicographically.
  const EdgeList& edges() const { return edges_; }
  // Unit normals of the rest faces, following the right-hand rule of each face's vertex order.
  const Points& face_normals() const { return face_normals_; }
  int num_vertices() const { return static_cast<int>(vertices_.rows()); }
  int num_faces() const { return static_cast<int>(faces_.rows()); }
  int dropped_faces() const { return dropped_faces_; }

  // True when every undirected edge is shared by exactly two faces that traverse it in opposite
  // directions: a closed, consistently oriented (watertight) surface.
  bool is_closed() const;

 private:
  std::string name_;
  Points vertices_;
  Triangles faces_;
  EdgeList edges_;
  Points face_normals_;
  int dropped_faces_ = 0;
};

// The mesh of `faces` (indices into `vertices`) with only the vertices they use, numbered in order
// of first use, and zero-area faces dropped (DegenerateFaces::kDrop): what loose triangles,
// welding, repair and simplification leave. Throws MeshError as TriangleMesh does.
TriangleMesh mesh_of_used_vertices(std::string name, const Points& vertices,
                                   std::span<const std::array<int, 3>> faces);

// The mesh seen in a mirror: its vertices reflected through its own y = 0 plane (y ↦ −y) and each
// face's winding reversed, so that its normals point outward again. Vertex and face numbers are
// kept, so per-vertex arrays of the two meshes correspond row by row.
TriangleMesh mirrored_mesh(const TriangleMesh& mesh);

// Unit normal of triangle (a, b, c) by the right-hand rule; zero for a degenerate triangle.
Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace fignet
