#include "fignet/bullet/scene_spec.h"

#include <Eigen/Eigenvalues>

#include "fignet/geometry/mass_properties.h"

namespace fignet::bullet {

BodySpec make_body(const TriangleMesh& mesh, double density, double friction, double restitution,
                   const std::vector<Points>& convex_parts) {
  const MassProperties props = compute_mass_properties(mesh);
  // Principal axes: the eigenvectors of the inertia tensor, as a proper rotation.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(props.inertia);
  Eigen::Matrix3d axes = solver.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1.0;
  // Symmetric shapes already sit on their principal axes; keep their frame rather than an
  // arbitrary eigenbasis of repeated moments.
  const bool diagonal = (props.inertia - Eigen::Matrix3d(props.inertia.diagonal().asDiagonal()))
                            .cwiseAbs()
                            .maxCoeff() <= 1e-9 * props.inertia.trace();
  if (diagonal) axes.setIdentity();
  Points vertices = (mesh.vertices().rowwise() - props.center_of_mass.transpose()) * axes;
  BodySpec body;
  body.mesh = std::make_shared<const TriangleMesh>(mesh.name(), std::move(vertices), mesh.faces());
  body.properties = {density * props.volume, friction, restitution};
  body.inertia = density * (axes.transpose() * props.inertia * axes).diagonal();
  if (convex_parts.size() > 1) {
    for (const Points& part : convex_parts) {
      body.convex_parts.push_back((part.rowwise() - props.center_of_mass.transpose()) * axes);
    }
  }
  return body;
}

}  // namespace fignet::bullet
