// Procedural shapes are closed, outward, and have the volume, centre of mass and inertia of the
// polyhedron they are (exact formulas), converging to the smooth shape's (within 1 %).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"

namespace fignet {
namespace {

constexpr double kPi = std::numbers::pi;

// Area of a regular n-gon inscribed in a circle of radius r.
double regular_polygon_area(int n, double r) {
  return 0.5 * n * r * r * std::sin(2 * kPi / n);
}

TEST(Shapes, EveryMoviShapeIsClosedWithPositiveVolume) {
  for (const std::string& name : movi_shape_names()) {
    SCOPED_TRACE(name);
    const TriangleMesh mesh = make_movi_shape(name);
    EXPECT_EQ(mesh.name(), name);
    EXPECT_TRUE(mesh.is_closed());
    EXPECT_GT(compute_mass_properties(mesh).volume, 0.0);
    // Spans about [-1, 1]^3 like Kubric's unit assets.
    EXPECT_LE(mesh.vertices().cwiseAbs().maxCoeff(), 1.2);
    EXPECT_GE(mesh.vertices().cwiseAbs().maxCoeff(), 0.7);
  }
  EXPECT_THROW(make_movi_shape("teapot"), ConfigError);
}

TEST(Shapes, VertexCountsFollowKubric) {
  EXPECT_EQ(make_movi_shape("sphere").num_vertices(), 64);
  EXPECT_EQ(make_movi_shape("cylinder").num_vertices(), 64);
  EXPECT_EQ(make_movi_shape("cube").num_vertices(), 56);  // Kubric: 51
}

TEST(Shapes, ConvexShapesHaveOutwardNormals) {
  for (const char* name : {"cube", "sphere", "cylinder", "cone"}) {
    SCOPED_TRACE(name);
    const TriangleMesh mesh = make_movi_shape(name);
    const Vec3 center = compute_mass_properties(mesh).center_of_mass;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      Vec3 centroid = Vec3::Zero();
      for (int k = 0; k < 3; ++k) centroid += mesh.vertices().row(mesh.faces()(f, k)).transpose();
      EXPECT_GT(mesh.face_normals().row(f).dot((centroid / 3 - center).transpose()), 0.0);
    }
  }
}

TEST(MassProperties, BoxIsExact) {
  const Vec3 h(0.5, 1.0, 2.0);
  const auto props = compute_mass_properties(make_box(h, 4));
  const double volume = 8 * h.prod();
  EXPECT_NEAR(props.volume, volume, 1e-12);
  EXPECT_NEAR(props.center_of_mass.norm(), 0.0, 1e-12);
  const Vec3 side = 2 * h;
  const Eigen::Vector3d expected(side.y() * side.y() + side.z() * side.z(),
                                 side.x() * side.x() + side.z() * side.z(),
                                 side.x() * side.x() + side.y() * side.y());
  EXPECT_TRUE(
      props.inertia.isApprox(Eigen::Matrix3d((volume / 12 * expected).asDiagonal()), 1e-12));
}

TEST(MassProperties, PrismsAndPyramidsMatchTheirFormulas) {
  const int n = 31;
  EXPECT_NEAR(compute_mass_properties(make_cylinder(1.0, 1.0, n)).volume,
              regular_polygon_area(n, 1.0) * 2.0, 1e-12);
  const auto cone = compute_mass_properties(make_cone(1.0, 2.0, n));
  EXPECT_NEAR(cone.volume, regular_polygon_area(n, 1.0) * 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(cone.center_of_mass.z(), -0.5, 1e-12);  // a quarter of the height above the base
  // Gear: the shoelace area of its profile times its thickness.
  const int teeth = 12;
  double area = 0.0;
  std::vector<Eigen::Vector2d> profile;
  for (int k = 0; k < 4 * teeth; ++k) {
    const double a = 2 * kPi * k / (4.0 * teeth), r = (k % 4 == 1 || k % 4 == 2) ? 1.0 : 0.8;
    profile.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  for (size_t k = 0; k < profile.size(); ++k) {
    const auto& p = profile[k];
    const auto& q = profile[(k + 1) % profile.size()];
    area += 0.5 * (p.x() * q.y() - q.x() * p.y());
  }
  EXPECT_NEAR(compute_mass_properties(make_gear(teeth, 0.8, 1.0, 0.3)).volume, area * 0.6, 1e-12);
  EXPECT_NEAR(compute_mass_properties(make_menger_sponge(1.0, 1)).volume, 8.0 * 20 / 27, 1e-12);
  EXPECT_NEAR(compute_mass_properties(make_menger_sponge(1.0, 2)).volume, 8.0 * 400 / 729, 1e-12);
}

TEST(MassProperties, FineMeshesConvergeToSmoothShapes) {
  EXPECT_NEAR(compute_mass_properties(make_sphere(1.0, 48, 96)).volume / (4.0 / 3 * kPi), 1.0,
              0.01);
  EXPECT_NEAR(compute_mass_properties(make_cylinder(1.0, 1.0, 96)).volume / (2 * kPi), 1.0, 0.01);
  EXPECT_NEAR(compute_mass_properties(make_cone(1.0, 2.0, 96)).volume / (2 * kPi / 3), 1.0, 0.01);
  const double torus = 2 * kPi * kPi * 0.7 * 0.3 * 0.3;
  EXPECT_NEAR(compute_mass_properties(make_torus(0.7, 0.3, 96, 48)).volume / torus, 1.0, 0.01);
  // Solid sphere inertia 2/5 m r^2, with m = volume at unit density.
  const auto sphere = compute_mass_properties(make_sphere(1.0, 48, 96));
  EXPECT_NEAR(sphere.inertia(0, 0) / (0.4 * 4.0 / 3 * kPi), 1.0, 0.02);
  EXPECT_NEAR(sphere.center_of_mass.norm(), 0.0, 1e-9);
}

TEST(MassProperties, SymmetricShapesAreCentredAndFarMeshesKeepPrecision) {
  for (const char* name : {"torus", "torus_knot", "gear", "sponge", "cube", "sphere", "cylinder"}) {
    EXPECT_NEAR(compute_mass_properties(make_movi_shape(name)).center_of_mass.norm(), 0.0, 1e-6)
        << name;
  }
  const TriangleMesh cube = make_box(Vec3::Ones());
  const Points far = cube.vertices().rowwise() + Eigen::RowVector3d(1000.0, -2000.0, 500.0);
  const auto props = compute_mass_properties(TriangleMesh("far", far, cube.faces()));
  EXPECT_NEAR(props.volume, 8.0, 1e-9);
  EXPECT_NEAR((props.center_of_mass - Vec3(1000, -2000, 500)).norm(), 0.0, 1e-9);
}

TEST(MassProperties, InwardMeshIsRejected) {
  const TriangleMesh cube = make_box(Vec3::Ones());
  Triangles inward = cube.faces();
  inward.col(1).swap(inward.col(2));
  EXPECT_THROW(compute_mass_properties(TriangleMesh("inward", cube.vertices(), inward)), MeshError);
}

TEST(Shapes, BadParametersNameTheShape) {
  try {
    make_torus(0.3, 0.7);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("torus"), std::string::npos);
  }
  EXPECT_THROW(make_box(Vec3(1, -1, 1)), ConfigError);
  EXPECT_THROW(make_sphere(1.0, 1, 8), ConfigError);
}

}  // namespace
}  // namespace fignet
