#include "fignet/bullet/scene_spec.h"

#include <Eigen/Eigenvalues>

#include <fmt/format.h>

#include <cmath>

#include "fignet/bullet/convex_decomposition.h"
#include "fignet/bullet/mesh_file.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"

namespace fignet::bullet {

BodySpec make_body(const TriangleMesh& mesh, const BodyInertia& inertia, double friction,
                   double restitution, const std::vector<Points>& convex_parts) {
  // Principal axes: the eigenvectors of the inertia tensor, as a proper rotation.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inertia.inertia);
  Eigen::Matrix3d axes = solver.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1.0;
  // Symmetric shapes already sit on their principal axes; keep their frame rather than an
  // arbitrary eigenbasis of repeated moments.
  const bool diagonal = (inertia.inertia - Eigen::Matrix3d(inertia.inertia.diagonal().asDiagonal()))
                            .cwiseAbs()
                            .maxCoeff() <= 1e-9 * inertia.inertia.trace();
  if (diagonal) axes.setIdentity();
  const Vec3& com = inertia.center_of_mass;
  Points vertices = (mesh.vertices().rowwise() - com.transpose()) * axes;
  BodySpec body;
  body.mesh = std::make_shared<const TriangleMesh>(mesh.name(), std::move(vertices), mesh.faces());
  body.properties = {inertia.mass, friction, restitution};
  body.inertia = (axes.transpose() * inertia.inertia * axes).diagonal();
  body.pose.position = com;
  body.pose.orientation = Eigen::Quaterniond(axes);
  // One part that is the mesh's own points adds nothing to the hull of the mesh.
  const bool redundant = convex_parts.size() == 1 &&
                         convex_parts.front().rows() == mesh.vertices().rows() &&
                         convex_parts.front() == mesh.vertices();
  if (!convex_parts.empty() && !redundant) {
    for (const Points& part : convex_parts) {
      body.convex_parts.push_back((part.rowwise() - com.transpose()) * axes);
    }
  }
  return body;
}

BodySpec make_body(const TriangleMesh& mesh, double density, double friction, double restitution,
                   const std::vector<Points>& convex_parts) {
  const MassProperties props = compute_mass_properties(mesh);
  return make_body(mesh, {density * props.volume, props.center_of_mass, density * props.inertia},
                   friction, restitution, convex_parts);
}

}  // namespace fignet::bullet

namespace fignet::bullet {

BodySpec make_body(const TriangleMesh& mesh, const BodyMaterial& material,
                   const MeshImportOptions& options) {
  const ImportedMesh imported = import_mesh(mesh, options);
  const UnitInertia unit = mesh_inertia(imported, options.inertia);
  double density = material.density;
  if (material.mass) {
    if (!(*material.mass > 0.0)) {
      throw ConfigError(
          fmt::format("mesh '{}': mass {} (must be > 0)", mesh.name(), *material.mass));
    }
    density = *material.mass / unit.mass;
  }
  if (!(density > 0.0)) {
    throw ConfigError(fmt::format("mesh '{}': density {} (must be > 0)", mesh.name(), density));
  }
  return make_body(imported.surface,
                   {density * unit.mass, unit.center_of_mass, density * unit.inertia},
                   material.friction, material.restitution, imported.convex_parts);
}

BodySpec load_body(const std::filesystem::path& mesh_file, const BodyMaterial& material,
                   double scale, const MeshImportOptions& options) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw ConfigError(
        fmt::format("mesh file '{}': scale {} (must be > 0)", mesh_file.string(), scale));
  }
  const TriangleMesh loaded = load_mesh_file(mesh_file);
  return make_body(TriangleMesh(loaded.name(), loaded.vertices() * scale, loaded.faces()), material,
                   options);
}

}  // namespace fignet::bullet
