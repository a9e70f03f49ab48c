// Volume, centre of mass and inertia of a closed triangle mesh, by the divergence theorem
// (signed tetrahedra from the origin), exact for the polyhedron.
#pragma once

#include <Eigen/Core>

#include "fignet/geometry/mesh.h"

namespace fignet {

struct MassProperties {
  double volume = 0.0;
  Vec3 center_of_mass = Vec3::Zero();
  // Inertia tensor about the centre of mass for unit density (multiply by density).
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

// Throws MeshError when the enclosed volume is not positive (open or inward-facing mesh).
MassProperties compute_mass_properties(const TriangleMesh& mesh);

// Mass spread over the surface instead of the volume (MuJoCo's shell inertia), for open meshes
// and thin-walled objects: area, centroid of the surface and inertia tensor about it for unit
// surface density (kg/m²). Any mesh with positive area works, open or closed, any winding.
struct ShellProperties {
  double area = 0.0;
  Vec3 center_of_mass = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};
ShellProperties compute_shell_properties(const TriangleMesh& mesh);

// The same mesh with its vertices expressed in its centre-of-mass frame (rest meshes handed to
// the graph builder and to Bullet bodies use this frame).
TriangleMesh centered_on_center_of_mass(const TriangleMesh& mesh);

}  // namespace fignet
