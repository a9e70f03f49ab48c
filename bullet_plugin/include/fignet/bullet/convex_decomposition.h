// Non-convex meshes as unions of convex pieces, so Bullet collides them as the shape they are
// (a torus can hang on a peg): convex meshes stay one hull, others go through Bullet's HACD
// (libbullet-extras).
#pragma once

#include <vector>

#include "fignet/geometry/mesh.h"

namespace fignet::bullet {

struct ConvexDecompositionOptions {
  // A mesh whose volume is within this fraction of its convex hull's is treated as convex.
  double convexity_tolerance = 0.01;
  // HACD's concavity threshold as a fraction of the bounding-box diagonal: lower gives more,
  // tighter pieces.
  double concavity = 0.02;
  int max_vertices_per_hull = 64;
  int min_parts = 1;
};

// Volume of the convex hull of `points` (Bullet's btConvexHullComputer).
double convex_hull_volume(const Points& points);

// Empty when the mesh is convex within the tolerance (one hull of its vertices is exact);
// otherwise the vertex sets of the convex pieces, in the mesh's frame. The mesh must be closed.
// Throws MeshError naming the mesh when HACD fails.
std::vector<Points> decompose_into_convex_parts(const TriangleMesh& mesh,
                                                const ConvexDecompositionOptions& options = {});

// The pieces Bullet should collide a closed mesh as: decompose_into_convex_parts, unless HACD
// failed on it: more than 256 pieces, or pieces whose hulls cover less than half the mesh's
// volume (HACD splits thin walls, such as an alpha wrap around an open cup, into slivers that
// cover a fraction of them). Then none, and `hacd_failed` (when given) is set: the mesh collides
// as its convex hull.
std::vector<Points> collision_parts(const TriangleMesh& mesh, bool* hacd_failed = nullptr,
                                    const ConvexDecompositionOptions& options = {});

}  // namespace fignet::bullet
