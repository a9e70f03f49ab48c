// Meshes as files give them: triangle soups with coincident vertices, degenerate and repeated
// faces, windings that disagree, several shells, holes. clean_mesh() welds and orients what can be
// kept and says what it found; wrap_mesh() (CGAL's 3D alpha wrapping) makes a closed, outward
// surface around what cannot be closed; simplify_mesh() (meshoptimizer) brings a mesh much finer
// than the model needs to a vertex budget within a stated tolerance.
#pragma once

#include <string>

#include "fignet/geometry/mesh.h"

namespace fignet {

// What clean_mesh() found and did. Counts refer to the mesh after welding.
struct MeshDefects {
  int welded_vertices = 0;      // vertices merged into another within the weld tolerance
  int degenerate_faces = 0;     // faces repeating a vertex or of negligible area: dropped
  int duplicate_faces = 0;      // faces on the same three vertices as an earlier one: dropped
  int shells = 0;               // pieces connected through shared edges
  int boundary_edges = 0;       // edges of one face only (holes, open surfaces)
  int non_manifold_edges = 0;   // edges shared by three or more faces
  int flipped_faces = 0;        // faces turned to agree with their neighbours' winding
  int inverted_shells = 0;      // shells turned outward (they enclosed negative volume)
  bool non_orientable = false;  // some shell cannot be wound consistently (Möbius-like)

  // Every edge between exactly two faces of opposite winding: the mesh encloses a volume.
  bool closed() const { return boundary_edges == 0 && non_manifold_edges == 0 && !non_orientable; }
  // Nothing was changed and the mesh is closed.
  bool clean() const;
  // One line for warnings, "2 shells, 14 open edges, 3 faces flipped", or "clean".
  std::string summary() const;
};

struct CleanMeshOptions {
  // Vertices closer than this fraction of the bounding-box diagonal are one vertex (exporters
  // split corners by normal and texture coordinate, and round differently per face).
  double weld_tolerance = 1e-7;
};

struct CleanedMesh {
  TriangleMesh mesh;  // welded, degenerate and repeated faces dropped, each shell wound outward
  MeshDefects defects;
};

// Welds coincident vertices, drops degenerate and repeated faces (a two-sided face keeps one
// side), winds each shell consistently (the majority's winding wins) and outward (positive
// enclosed volume; for open shells, about the shell's centroid). Unused vertices are dropped.
// Throws MeshError naming `name` when a vertex is not finite, an index is out of range, or no face
// is left.
CleanedMesh clean_mesh(std::string name, const Points& vertices, const Triangles& faces,
                       const CleanMeshOptions& options = {});

// True when this build has CGAL's alpha wrapping (FIGNET_WITH_CGAL).
bool mesh_wrapping_available();

struct WrapOptions {
  // The wrap's alpha (how narrow a gap or hole it closes over) and offset (how far it lies
  // outside the input), as fractions of the bounding-box diagonal: CGAL's suggested defaults.
  double relative_alpha = 1.0 / 20.0;
  double relative_offset = 1.0 / 600.0;
};

// A closed, 2-manifold, outward surface around any triangle set (open, non-manifold, self-
// intersecting, several shells): CGAL::alpha_wrap_3. It lies outside the input by about the offset.
// Throws ConfigError when the build has no CGAL, MeshError when the wrap fails.
TriangleMesh wrap_mesh(const TriangleMesh& mesh, const WrapOptions& options = {});

struct SimplifyOptions {
  int max_vertices = 1000;  // the budget; a mesh already within it is returned as it is
  // The largest distance the simplified surface may deviate, as a fraction of the mesh's largest
  // bounding-box side; simplification stops there even above the budget.
  double tolerance = 0.01;
};

struct SimplifiedMesh {
  TriangleMesh mesh;
  double error = 0.0;    // deviation meshoptimizer reports, in the mesh's units
  bool changed = false;  // false: the mesh was within the budget (or could not be reduced)
  bool closed = true;    // the result is closed (simplification keeps topology when it can)
};

// Edge-collapse simplification (meshoptimizer's meshopt_simplify) toward `max_vertices`, within
// the tolerance; topology and borders are kept. Throws ConfigError for a budget below 4 or a
// tolerance outside (0, 1].
SimplifiedMesh simplify_mesh(const TriangleMesh& mesh, const SimplifyOptions& options = {});

}  // namespace fignet
