// Meshes as people have them, made into bodies: cleaned (welded, wound consistently and
// outward), repaired into a closed surface where they are open or broken, simplified to the graph's
// vertex budget, with mass and inertia by a choice like MuJoCo's mesh inertia modes. One warning
// line says what was wrong with a mesh and what was done about it.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "fignet/geometry/mesh_repair.h"

namespace fignet::bullet {

// Where a mesh's mass and inertia come from (MuJoCo's <mesh inertia=…>).
enum class MeshInertia {
  kAuto,        // the enclosed volume when the mesh is closed, otherwise the convex hull's
  kVolume,      // the enclosed volume; a mesh that is not closed is an error
  kConvexHull,  // the convex hull's volume, whatever the mesh
  kShell,       // spread over the surface: density is then in kg per m² of surface
};

// "auto", "volume", "convex" or "shell"; the parser throws ConfigError listing them.
const char* mesh_inertia_name(MeshInertia inertia);
MeshInertia parse_mesh_inertia(const std::string& name);

struct MeshImportOptions {
  MeshInertia inertia = MeshInertia::kAuto;
  // An open or broken mesh has no outward normals FIGNet can trust: it is replaced for the graph
  // by a closed surface (CGAL's alpha wrap, or its convex hull in a build without CGAL).
  // false: the graph sees the cleaned mesh as it is.
  bool repair = true;
  WrapOptions wrap;
  // The node budget: a mesh with more vertices is simplified for the graph (meshoptimizer),
  // within `simplify_tolerance` of its largest side; Bullet's collision shape keeps the full
  // mesh. MOVi's finest shape (the torus knot) has 960 vertices. 0: no budget.
  int max_graph_vertices = 1000;
  double simplify_tolerance = 0.01;
  // Receives the one warning line for a mesh that needed anything; default: standard error.
  std::function<void(const std::string&)> warn;
};

// A mesh ready to become a body, everything in the mesh's own frame.
struct ImportedMesh {
  TriangleMesh surface;  // what FIGNet sees: closed and outward where it could be made so
  TriangleMesh cleaned;  // the mesh welded and wound consistently, at full resolution
  MeshDefects defects;   // what cleaning found
  std::string repair;    // "", "alpha wrap" or "convex hull"
  int vertices_before_simplification = 0;
  double simplification_error = 0.0;  // metres (mesh units); 0 when not simplified
  // Bullet's collision shape: the convex pieces of the full-resolution mesh; empty: the hull of
  // `surface`'s vertices is exact.
  std::vector<Points> convex_parts;
  // HACD's pieces did not stand for the surface (they cover less than half of it, as on the thin
  // walls of an open mesh's wrap, or number over 256): Bullet collides the mesh's convex hull.
  bool hull_collision = false;

  bool simplified() const { return vertices_before_simplification > surface.num_vertices(); }
  // The cleaned mesh encloses a volume (every edge between two faces of opposite winding).
  bool closed() const { return defects.closed() && cleaned.is_closed(); }
  // What was done, for the warning line ("" when the mesh needed nothing).
  std::string actions() const;
};

// Cleans, repairs and simplifies `mesh` (any triangles in any frame) under `options`, and sends
// one warning naming the mesh when it needed any of it. Throws MeshError naming the mesh when
// nothing usable is left.
ImportedMesh import_mesh(const TriangleMesh& mesh, const MeshImportOptions& options = {});

// Mass properties for unit density (kg/m³, or kg/m² for kShell) under `inertia`, in the mesh's
// frame: `mass` is the volume (or area). Throws MeshError naming the mesh when the mode cannot
// apply (kVolume of an open mesh; a flat mesh has no hull volume).
struct UnitInertia {
  double mass = 0.0;
  Vec3 center_of_mass = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  // How mass and inertia grow with a uniform scale s: s³ and s⁵ for volumes, s² and s⁴ for shells.
  int mass_scale_power = 3;
};
UnitInertia mesh_inertia(const ImportedMesh& mesh, MeshInertia inertia);

}  // namespace fignet::bullet
