#include <gtest/gtest.h>

#include <cmath>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/mesh.h"
#include "fignet/geometry/shapes.h"

namespace fignet {
namespace {

Points tetrahedron_vertices() {
  Points v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return v;
}

Triangles tetrahedron_faces() {
  Triangles f(4, 3);
  f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return f;
}

// Runs `make` and returns the MeshError message (failing the test if none is thrown).
template <class Make>
std::string mesh_error(Make make) {
  try {
    make();
  } catch (const MeshError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no MeshError thrown";
  return {};
}

TEST(TriangleMesh, DerivesUniqueEdgesAndOutwardNormals) {
  const TriangleMesh mesh("tet", tetrahedron_vertices(), tetrahedron_faces());
  EXPECT_EQ(mesh.edges().rows(), 6);
  for (Eigen::Index e = 0; e < mesh.edges().rows(); ++e) {
    EXPECT_LT(mesh.edges()(e, 0), mesh.edges()(e, 1));
  }
  // Face 0 is the z = 0 face: outward is -z. Face 3 is the slanted face: (1,1,1)/sqrt(3).
  EXPECT_TRUE(mesh.face_normals().row(0).isApprox(Eigen::RowVector3d(0, 0, -1)));
  EXPECT_TRUE(mesh.face_normals().row(3).isApprox(Eigen::RowVector3d(1, 1, 1) / std::sqrt(3.0)));
  EXPECT_TRUE(mesh.is_closed());
}

TEST(TriangleMesh, OpenAndInconsistentMeshesAreNotClosed) {
  Triangles open = tetrahedron_faces().topRows(3);
  EXPECT_FALSE(TriangleMesh("open", tetrahedron_vertices(), open).is_closed());
  Triangles flipped = tetrahedron_faces();
  flipped.row(3) << 1, 3, 2;
  EXPECT_FALSE(TriangleMesh("flipped", tetrahedron_vertices(), flipped).is_closed());
}

TEST(TriangleMesh, MirroredMeshIsTheReflectedSolidWithOutwardNormals) {
  // A torus knot has a handedness: its mirror is another solid, of the same volume, with the
  // reflected centre of mass and inertia (M·I·M for the reflection M), face for face. Tilted and
  // moved off the origin, so that neither has a zero the reflection would leave as it is.
  const TriangleMesh upright = make_torus_knot(2, 3, 1.0, 0.2, 48, 8);
  const Eigen::Matrix3d tilt =
      Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Points tilted = upright.vertices() * tilt.transpose();
  tilted.rowwise() += Eigen::RowVector3d(0.1, 0.2, 0.3);
  const TriangleMesh knot("knot", tilted, upright.faces());
  const TriangleMesh mirror = mirrored_mesh(knot);
  const Eigen::DiagonalMatrix<double, 3> reflect(1.0, -1.0, 1.0);
  ASSERT_EQ(mirror.num_vertices(), knot.num_vertices());
  ASSERT_EQ(mirror.num_faces(), knot.num_faces());
  EXPECT_TRUE((mirror.vertices() - knot.vertices() * reflect).isZero(0.0));
  EXPECT_TRUE((mirror.face_normals() - knot.face_normals() * reflect).isZero(1e-12));
  EXPECT_TRUE((mirror.edges() - knot.edges()).isZero());
  EXPECT_TRUE(mirror.is_closed());
  const MassProperties a = compute_mass_properties(knot), b = compute_mass_properties(mirror);
  EXPECT_NEAR(b.volume, a.volume, 1e-12 * a.volume);
  EXPECT_TRUE(b.center_of_mass.isApprox(reflect * a.center_of_mass, 1e-9));
  const Eigen::Matrix3d reflected_inertia = reflect * a.inertia * reflect;
  EXPECT_TRUE(b.inertia.isApprox(reflected_inertia, 1e-9));
  EXPECT_GT(std::abs(a.inertia(0, 1)), 1e-3 * a.inertia.norm());  // the reflection changes it
  // The mirror's mirror is the mesh itself.
  const TriangleMesh back = mirrored_mesh(mirror);
  EXPECT_TRUE((back.vertices() - knot.vertices()).isZero(0.0));
  EXPECT_TRUE((back.faces() - knot.faces()).isZero());
}

TEST(TriangleMesh, RejectsNonFiniteVertexNamingIt) {
  Points v = tetrahedron_vertices();
  v(2, 1) = NAN;
  const std::string message = mesh_error([&] { TriangleMesh("bad", v, tetrahedron_faces()); });
  EXPECT_NE(message.find("mesh 'bad'"), std::string::npos) << message;
  EXPECT_NE(message.find("vertex 2"), std::string::npos) << message;
}

TEST(TriangleMesh, RejectsIndexOutOfRange) {
  Triangles f = tetrahedron_faces();
  f(1, 2) = 7;
  const std::string message = mesh_error([&] { TriangleMesh("m", tetrahedron_vertices(), f); });
  EXPECT_NE(message.find("face 1 references vertex 7"), std::string::npos) << message;
  f(1, 2) = -1;
  EXPECT_THROW(TriangleMesh("m", tetrahedron_vertices(), f), MeshError);
}

TEST(TriangleMesh, RejectsNoFacesAndRepeatedVertices) {
  EXPECT_NE(mesh_error([] {
              TriangleMesh("empty", tetrahedron_vertices(), Triangles(0, 3));
            }).find("no faces"),
            std::string::npos);
  Triangles f = tetrahedron_faces();
  f.row(2) << 1, 1, 3;
  EXPECT_NE(mesh_error([&] { TriangleMesh("m", tetrahedron_vertices(), f); }).find("repeats"),
            std::string::npos);
}

TEST(TriangleMesh, DegenerateFacesAreRejectedByDefaultOrDropped) {
  Points v(5, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 2, 0, 0;  // vertex 4 is collinear with 0 and 1
  Triangles f(5, 3);
  f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 0, 1, 4;
  const std::string message = mesh_error([&] { TriangleMesh("sliver", v, f); });
  EXPECT_NE(message.find("face 4 is degenerate"), std::string::npos) << message;

  const TriangleMesh dropped("sliver", v, f, {.degenerate_faces = DegenerateFaces::kDrop});
  EXPECT_EQ(dropped.num_faces(), 4);
  EXPECT_EQ(dropped.dropped_faces(), 1);
  EXPECT_TRUE(dropped.is_closed());
  // A thin but valid triangle stays: the threshold is relative to the mesh size.
  v.row(4) << 0.5, 1e-5, 0;
  EXPECT_NO_THROW(TriangleMesh("thin", v, f));
}

TEST(TriangleMesh, AllFacesDegenerateIsAnError) {
  Points v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  Triangles f(1, 3);
  f << 0, 1, 2;
  EXPECT_THROW(TriangleMesh("line", v, f, {.degenerate_faces = DegenerateFaces::kDrop}), MeshError);
}

}  // namespace
}  // namespace fignet
