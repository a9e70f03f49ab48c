#include "fignet/geometry/mass_properties.h"

#include <fmt/format.h>

#include "fignet/error.h"

namespace fignet {

namespace {

// Measure (volume or area), first moment ∫ x and second moment ∫ x xᵀ of a mass distribution.
struct Moments {
  double measure = 0.0;
  Vec3 first = Vec3::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
};

// The signed tetrahedron (0, a, b, c).
Moments tetrahedron_moments(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double det = a.dot(b.cross(c));
  const Vec3 sum = a + b + c;
  return {det / 6.0, det / 24.0 * sum,
          det / 120.0 *
              (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose())};
}

// The triangle (a, b, c) as a lamina: ∫ x xᵀ dA = A / 12 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b +
// c.
Moments triangle_moments(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const Vec3 sum = a + b + c;
  return {area, area / 3.0 * sum,
          area / 12.0 *
              (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose())};
}

// The faces' moments summed about the vertex centroid rather than the origin: a mesh far from the
// origin would otherwise lose precision in large cancelling terms.
template <class FaceMoments>
Moments integrate_faces(const TriangleMesh& mesh, const Vec3& origin, FaceMoments face_moments) {
  Moments total;
  for (Eigen::Index f = 0; f < mesh.faces().rows(); ++f) {
    const auto& face = mesh.faces().row(f);
    const Moments m = face_moments(Vec3(mesh.vertices().row(face(0))) - origin,
                                   Vec3(mesh.vertices().row(face(1))) - origin,
                                   Vec3(mesh.vertices().row(face(2))) - origin);
    total.measure += m.measure;
    total.first += m.first;
    total.second += m.second;
  }
  return total;
}

// Centre of mass and the inertia tensor about it (unit density) from moments about `origin`.
void central_inertia(const Moments& m, const Vec3& origin, Vec3& center_of_mass,
                     Eigen::Matrix3d& inertia) {
  const Vec3 local_com = m.first / m.measure;
  center_of_mass = origin + local_com;
  const Eigen::Matrix3d central = m.second - m.measure * local_com * local_com.transpose();
  inertia = central.trace() * Eigen::Matrix3d::Identity() - central;
}

}  // namespace

MassProperties compute_mass_properties(const TriangleMesh& mesh) {
  const Vec3 origin = mesh.vertices().colwise().mean();
  const Moments m = integrate_faces(mesh, origin, tetrahedron_moments);
  if (!(m.measure > 0.0)) {
    throw MeshError(fmt::format(
        "mesh '{}': encloses volume {:.6g}; a closed, outward-oriented mesh is required",
        mesh.name(), m.measure));
  }
  MassProperties result;
  result.volume = m.measure;
  central_inertia(m, origin, result.center_of_mass, result.inertia);
  return result;
}

ShellProperties compute_shell_properties(const TriangleMesh& mesh) {
  const Vec3 origin = mesh.vertices().colwise().mean();
  const Moments m = integrate_faces(mesh, origin, triangle_moments);
  if (!(m.measure > 0.0)) {
    throw MeshError(fmt::format("mesh '{}': surface area {:.6g}; a shell needs a positive area",
                                mesh.name(), m.measure));
  }
  ShellProperties result;
  result.area = m.measure;
  central_inertia(m, origin, result.center_of_mass, result.inertia);
  return result;
}

TriangleMesh centered_on_center_of_mass(const TriangleMesh& mesh) {
  const Vec3 com = compute_mass_properties(mesh).center_of_mass;
  Points vertices = mesh.vertices().rowwise() - com.transpose();
  return TriangleMesh(mesh.name(), std::move(vertices), mesh.faces());
}

}  // namespace fignet
