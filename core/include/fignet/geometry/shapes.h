// Procedural closed, outward-oriented triangle meshes for the Kubric MOVi shapes and the
// pushing scene's prisms. Unit shapes span about [-1, 1]^3, like Kubric's KuBasic assets, and are
// scaled by the scene (MOVi-A uses 0.7 or 1.4). Vertices are in the shape's own frame; use
// centered_on_center_of_mass() for a body frame.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fignet/geometry/mesh.h"

namespace fignet {

// Box with each face split into segments x segments squares. segments = 3 gives 56 vertices
// (Kubric's cube has 51, from a different triangulation of the same surface).
TriangleMesh make_box(const Vec3& half_extents, int segments = 3);
// Sphere of `rings` latitude rings of `segments` vertices, capped by polygons (8 x 8 = 64 vertices,
// as Kubric's).
TriangleMesh make_sphere(double radius, int rings = 8, int segments = 8);
// Cylinder along z with capped ends and a centre vertex on each cap (31 segments = 64 vertices).
TriangleMesh make_cylinder(double radius, double half_height, int segments = 31);
// Cone along z, base at z = -height/2, apex at +height/2.
TriangleMesh make_cone(double radius, double height, int segments = 31);
// Capsule along z: a cylinder of the given half height between two hemispheres of `cap_rings`
// rings each (Bullet's btCapsuleShapeZ).
TriangleMesh make_capsule(double radius, double half_height, int cap_rings = 4, int segments = 16);
// Torus around z.
TriangleMesh make_torus(double major_radius, double minor_radius, int major_segments = 32,
                        int minor_segments = 12);
// (p, q) torus knot tube.
TriangleMesh make_torus_knot(int p = 2, int q = 3, double scale = 0.3, double tube_radius = 0.1,
                             int segments = 120, int tube_segments = 8);
// Spur gear along z: `teeth` trapezoidal teeth between root and tip radii.
TriangleMesh make_gear(int teeth = 12, double root_radius = 0.8, double tip_radius = 1.0,
                       double half_thickness = 0.3);
// Menger sponge of the given level (level 1 = 20 of 27 sub-cubes) filling [-h, h]^3.
TriangleMesh make_menger_sponge(double half_extent, int level = 1);
// Right prism along z over a polygon that is star-shaped about the origin (counter-clockwise),
// with a centre vertex on each cap.
TriangleMesh make_prism(std::string name, std::span<const Eigen::Vector2d> polygon,
                        double half_height);

// Names accepted by make_movi_shape(), in MOVi-B order: cube, cylinder, sphere, cone, torus,
// torus_knot, gear, sponge.
const std::vector<std::string>& movi_shape_names();
// The unit MOVi shape called `name` (throws ConfigError naming the valid names otherwise).
TriangleMesh make_movi_shape(std::string_view name);

// An exact decomposition of make_movi_shape(name) into convex pieces, each given by its vertices
// (a subset of the mesh's, or for the sponge its voxel corners), in the mesh's frame: one piece for
// the convex shapes; consecutive ring pairs of the torus and torus knot tubes; the root polygon and
// one quadrilateral prism per tooth of the gear; the 20 cubes of the sponge. Physics engines
// collide the union of the pieces' convex hulls, so a torus can hang on a peg.
std::vector<Points> movi_convex_parts(std::string_view name);

}  // namespace fignet
