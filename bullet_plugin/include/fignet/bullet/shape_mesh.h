// Bullet collision shapes as the triangle meshes FIGNet reasons about. Convex and compound shapes
// are converted once and cached (per shape and local scaling); static triangle meshes are cut
// per step to the triangles near the bodies that touch them, so their cost does not grow with
// their size.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "fignet/geometry/mesh_repair.h"

class btCollisionShape;
class btConcaveShape;
class btVector3;

namespace fignet::bullet {

// The mesh of a convex or compound shape in the shape's frame (a rigid body's centre-of-mass
// frame): box, sphere, cylinder and cone (any axis), capsule, convex hull, any other convex shape
// through btShapeHull, and compounds of these (child transforms applied, recursively). Local
// scaling is applied; boxes and cylinders include their margin (Bullet keeps it inside them),
// hulls are the hull of their points. Throws ConfigError naming the shape type otherwise.
TriangleMesh shape_to_mesh(const btCollisionShape& shape);

// The triangles of a concave shape (btBvhTriangleMeshShape and other btConcaveShapes) that overlap
// the box [lower, upper] in the shape's frame, welded into one mesh; null when none do.
std::unique_ptr<TriangleMesh> concave_triangles_in_box(const btConcaveShape& shape,
                                                       const btVector3& lower,
                                                       const btVector3& upper);

// Converts each convex or compound shape once. Not thread-safe (one per world).
class ShapeMeshCache {
 public:
  // Meshes above `budget.max_vertices` are simplified (once) before they are handed out, so a
  // body's cost in the graph follows the model's resolution, not the mesh's. Default: no budget.
  ShapeMeshCache() = default;
  explicit ShapeMeshCache(const SimplifyOptions& budget) : budget_(budget) {}
  std::shared_ptr<const TriangleMesh> mesh_of(const btCollisionShape& shape);
  // Makes `mesh` the shape's mesh at its current local scaling.
  void set_mesh(const btCollisionShape& shape, std::shared_ptr<const TriangleMesh> mesh);
  void clear() { meshes_.clear(); }
  size_t size() const { return meshes_.size(); }

 private:
  // Keyed by shape and local scaling: the same shape rescaled is another mesh.
  std::map<std::pair<const btCollisionShape*, std::array<double, 3>>,
           std::shared_ptr<const TriangleMesh>>
      meshes_;
  std::optional<SimplifyOptions> budget_;

  std::shared_ptr<const TriangleMesh> within_budget(std::shared_ptr<const TriangleMesh> mesh) const;
};

}  // namespace fignet::bullet
