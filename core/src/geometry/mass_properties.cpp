#include "fignet/geometry/mass_properties.h"

#include <fmt/format.h>

#include "fignet/error.h"

namespace fignet {

namespace {

// Integrals over a signed tetrahedron (0, a, b, c): volume and second moment ∫ x xᵀ dV.
struct TetrahedronIntegrals {
  double volume;
  Vec3 first_moment;
  Eigen::Matrix3d second_moment;
};

TetrahedronIntegrals integrate_tetrahedron(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double det = a.dot(b.cross(c));
  const Vec3 sum = a + b + c;
  TetrahedronIntegrals t;
  t.volume = det / 6.0;
  t.first_moment = t.volume * sum / 4.0;
  t.second_moment =
      det / 120.0 *
      (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
  return t;
}

}  // namespace

MassProperties compute_mass_properties(const TriangleMesh& mesh) {
  // Integrate about the vertex centroid rather than the origin: a mesh far from the origin would
  // otherwise lose precision in the large cancelling tetrahedra.
  const Vec3 origin = mesh.vertices().colwise().mean();
  double volume = 0.0;
  Vec3 first = Vec3::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (Eigen::Index f = 0; f < mesh.faces().rows(); ++f) {
    const auto& face = mesh.faces().row(f);
    const TetrahedronIntegrals t = integrate_tetrahedron(
        Vec3(mesh.vertices().row(face(0))) - origin, Vec3(mesh.vertices().row(face(1))) - origin,
        Vec3(mesh.vertices().row(face(2))) - origin);
    volume += t.volume;
    first += t.first_moment;
    second += t.second_moment;
  }
  if (!(volume > 0.0)) {
    throw MeshError(fmt::format(
        "mesh '{}': encloses volume {:.6g}; a closed, outward-oriented mesh is required",
        mesh.name(), volume));
  }
  MassProperties result;
  result.volume = volume;
  const Vec3 local_com = first / volume;
  result.center_of_mass = origin + local_com;
  const Eigen::Matrix3d central = second - volume * local_com * local_com.transpose();
  result.inertia = central.trace() * Eigen::Matrix3d::Identity() - central;
  return result;
}

TriangleMesh centered_on_center_of_mass(const TriangleMesh& mesh) {
  const Vec3 com = compute_mass_properties(mesh).center_of_mass;
  Points vertices = mesh.vertices().rowwise() - com.transpose();
  return TriangleMesh(mesh.name(), std::move(vertices), mesh.faces());
}

}  // namespace fignet
