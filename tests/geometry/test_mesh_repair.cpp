// clean_mesh, wrap_mesh, simplify_mesh and shell inertia on small meshes with one defect each,
// against what the intact mesh gives (volumes, closedness) and analytic values.
#include <gtest/gtest.h>

#include <cmath>

#include "../error_text.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/mesh_repair.h"
#include "fignet/geometry/shapes.h"

namespace fignet {
namespace {

using testing::error_of;

// Every face with its own three corners: a soup, as STL files store meshes.
Points soup_vertices(const TriangleMesh& mesh) {
  Points v(3 * mesh.num_faces(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) v.row(3 * f + k) = mesh.vertices().row(mesh.faces()(f, k));
  return v;
}
Triangles soup_faces(int count) {
  Triangles f(count, 3);
  for (int i = 0; i < count; ++i) f.row(i) << 3 * i, 3 * i + 1, 3 * i + 2;
  return f;
}

double volume_of(const TriangleMesh& mesh) {
  return compute_mass_properties(mesh).volume;
}

TEST(CleanMesh, LeavesAClosedMeshAsItIs) {
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 2);
  const CleanedMesh cleaned = clean_mesh("cube", cube.vertices(), cube.faces());
  EXPECT_TRUE(cleaned.defects.clean()) << cleaned.defects.summary();
  EXPECT_EQ(cleaned.defects.summary(), "clean");
  EXPECT_EQ(cleaned.mesh.num_vertices(), cube.num_vertices());
  EXPECT_EQ(cleaned.mesh.num_faces(), cube.num_faces());
  EXPECT_NEAR(volume_of(cleaned.mesh), 1.0, 1e-12);
}

TEST(CleanMesh, WeldsATriangleSoupIntoTheClosedMesh) {
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 2);
  Points soup = soup_vertices(cube);
  soup.array() += 1e-9 * Points::Random(soup.rows(), 3).array();  // exporters' rounding
  const CleanedMesh cleaned = clean_mesh("soup", soup, soup_faces(cube.num_faces()));
  EXPECT_EQ(cleaned.mesh.num_vertices(), cube.num_vertices());
  EXPECT_EQ(cleaned.defects.welded_vertices, soup.rows() - cube.num_vertices());
  EXPECT_TRUE(cleaned.defects.closed());
  EXPECT_TRUE(cleaned.mesh.is_closed());
  EXPECT_NEAR(volume_of(cleaned.mesh), 1.0, 1e-6);
}

TEST(CleanMesh, RewindsFlippedFacesToTheMajority) {
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 2);
  Triangles faces = cube.faces();
  for (int f : {0, 5, 9}) std::swap(faces(f, 1), faces(f, 2));
  const CleanedMesh cleaned = clean_mesh("flipped", cube.vertices(), faces);
  EXPECT_EQ(cleaned.defects.flipped_faces, 3);
  EXPECT_EQ(cleaned.defects.inverted_shells, 0);
  EXPECT_TRUE(cleaned.mesh.is_closed());
  EXPECT_NEAR(volume_of(cleaned.mesh), 1.0, 1e-12);
}

TEST(CleanMesh, TurnsAnInsideOutShellOutward) {
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 2);
  Triangles faces = cube.faces();
  faces.col(1).swap(faces.col(2));
  const CleanedMesh cleaned = clean_mesh("inside out", cube.vertices(), faces);
  EXPECT_EQ(cleaned.defects.inverted_shells, 1);
  EXPECT_NEAR(volume_of(cleaned.mesh), 1.0, 1e-12);
}

TEST(CleanMesh, DropsTwoSidedDuplicateAndDegenerateFaces) {
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 1);
  const Eigen::Index n = cube.num_faces();
  Triangles faces(n + 4, 3);
  faces.topRows(n) = cube.faces();
  faces.row(n) << cube.faces()(0, 0), cube.faces()(0, 2), cube.faces()(0, 1);  // back side
  faces.row(n + 1) = cube.faces().row(3);                                      // repeated
  faces.row(n + 2) << 0, 0, 1;                                                 // collapsed
  Points vertices(cube.num_vertices() + 1, 3);
  vertices << cube.vertices(), 0.5 * (cube.vertices().row(0) + cube.vertices().row(1));
  faces.row(n + 3) << 0, 1, cube.num_vertices();  // zero area: its corners are collinear
  const CleanedMesh cleaned = clean_mesh("messy", vertices, faces);
  EXPECT_EQ(cleaned.defects.duplicate_faces, 2);
  EXPECT_EQ(cleaned.defects.degenerate_faces, 2);
  EXPECT_EQ(cleaned.mesh.num_faces(), n);
  EXPECT_EQ(cleaned.mesh.num_vertices(), cube.num_vertices());  // the unused midpoint is gone
  EXPECT_TRUE(cleaned.mesh.is_closed());
}

TEST(CleanMesh, CountsShellsAndKeepsEachOutward) {
  const TriangleMesh a = make_box(Vec3::Constant(0.5), 1);
  const TriangleMesh b = make_sphere(0.3, 6, 8);
  Points vertices(a.num_vertices() + b.num_vertices(), 3);
  vertices << a.vertices(), b.vertices().rowwise() + Eigen::RowVector3d(3, 0, 0);
  Triangles faces(a.num_faces() + b.num_faces(), 3);
  faces << a.faces(), b.faces().array() + a.num_vertices();
  faces.bottomRows(b.num_faces()).col(1).swap(faces.bottomRows(b.num_faces()).col(2));
  const CleanedMesh cleaned = clean_mesh("two shells", vertices, faces);
  EXPECT_EQ(cleaned.defects.shells, 2);
  EXPECT_EQ(cleaned.defects.inverted_shells, 1);
  EXPECT_TRUE(cleaned.mesh.is_closed());
  EXPECT_NEAR(volume_of(cleaned.mesh), volume_of(a) + volume_of(b), 1e-9);
  EXPECT_NE(cleaned.defects.summary().find("2 shells"), std::string::npos);
}

TEST(CleanMesh, ReportsHolesAndNonManifoldEdges) {
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 1);
  // An open box: the last two triangles (one side) are missing; its rim has four open edges.
  const CleanedMesh open =
      clean_mesh("open box", cube.vertices(), cube.faces().topRows(cube.num_faces() - 2));
  EXPECT_EQ(open.defects.boundary_edges, 4);
  EXPECT_FALSE(open.defects.closed());
  EXPECT_FALSE(open.mesh.is_closed());
  // Outward about the centroid even though it encloses nothing.
  const Vec3 centroid = open.mesh.vertices().colwise().mean();
  for (int f = 0; f < open.mesh.num_faces(); ++f) {
    const Vec3 centre = (open.mesh.vertices().row(open.mesh.faces()(f, 0)) +
                         open.mesh.vertices().row(open.mesh.faces()(f, 1)) +
                         open.mesh.vertices().row(open.mesh.faces()(f, 2)))
                            .transpose() /
                        3.0;
    EXPECT_GT(open.mesh.face_normals().row(f).dot(centre - centroid), 0.0) << "face " << f;
  }
  // Three fins on one edge.
  Points fin(5, 3);
  fin << 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0, -1, -1, 0;
  Triangles fins(3, 3);
  fins << 0, 1, 2, 0, 1, 3, 0, 1, 4;
  const CleanedMesh book = clean_mesh("book", fin, fins);
  EXPECT_EQ(book.defects.non_manifold_edges, 1);
  EXPECT_NE(book.defects.summary().find("1 non-manifold edge"), std::string::npos);
}

TEST(CleanMesh, NamesTheMeshInErrors) {
  Points v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 0, std::nan(""), 0;
  Triangles f(1, 3);
  f << 0, 1, 2;
  EXPECT_NE(error_of<MeshError>([&] { clean_mesh("bad.obj", v, f); }).find("'bad.obj'"),
            std::string::npos);
  v(2, 1) = 1;
  f << 0, 1, 7;
  EXPECT_NE(error_of<MeshError>([&] { clean_mesh("bad.obj", v, f); }).find("vertex 7"),
            std::string::npos);
  f << 0, 0, 1;
  EXPECT_NE(error_of<MeshError>([&] { clean_mesh("bad.obj", v, f); }).find("degenerate"),
            std::string::npos);
}

TEST(ShellProperties, MatchTheHollowCube) {
  // A hollow cube of side L and mass M: I = 5/18 M L² about every axis through its centre.
  const double side = 2.0;
  const TriangleMesh cube = make_box(Vec3::Constant(side / 2), 3);
  const ShellProperties shell = compute_shell_properties(cube);
  EXPECT_NEAR(shell.area, 6 * side * side, 1e-12);
  EXPECT_NEAR(shell.center_of_mass.norm(), 0.0, 1e-12);
  const double expected = 5.0 / 18.0 * shell.area * side * side;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(shell.inertia(k, k), expected, 1e-9 * expected);
  EXPECT_NEAR((shell.inertia - Eigen::Matrix3d(shell.inertia.diagonal().asDiagonal())).norm(), 0.0,
              1e-9);
}

TEST(ShellProperties, OfAnOpenSurfaceIgnoreWinding) {
  // A unit square plate in z = 0: area 1, centroid at its middle, I_zz = (1 + 1) / 12.
  Points v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  Triangles f(2, 3);
  f << 0, 1, 2, 0, 3, 2;  // opposite windings
  const ShellProperties plate = compute_shell_properties(TriangleMesh("plate", v, f));
  EXPECT_NEAR(plate.area, 1.0, 1e-12);
  EXPECT_TRUE(plate.center_of_mass.isApprox(Vec3(0.5, 0.5, 0), 1e-12));
  EXPECT_NEAR(plate.inertia(2, 2), 2.0 / 12.0, 1e-12);
  EXPECT_NEAR(plate.inertia(0, 0), 1.0 / 12.0, 1e-12);
}

TEST(SimplifyMesh, BringsAFineSphereToTheBudgetWithinTolerance) {
  const TriangleMesh fine = make_sphere(0.5, 140, 143);
  ASSERT_GT(fine.num_vertices(), 19000);
  SimplifyOptions options;
  options.max_vertices = 400;
  options.tolerance = 0.02;
  const SimplifiedMesh coarse = simplify_mesh(fine, options);
  EXPECT_TRUE(coarse.changed);
  EXPECT_LE(coarse.mesh.num_vertices(), 400);
  EXPECT_GT(coarse.mesh.num_vertices(), 100);
  EXPECT_TRUE(coarse.closed);
  EXPECT_TRUE(coarse.mesh.is_closed());
  // Its vertices are the sphere's (edge collapse keeps positions); its faces stay within the
  // tolerance of the largest side (1 m) of the sphere: the face centres' radius says so.
  EXPECT_LE(coarse.error, 0.02 * 1.0);
  for (int f = 0; f < coarse.mesh.num_faces(); ++f) {
    Vec3 centre = Vec3::Zero();
    for (int k = 0; k < 3; ++k) centre += coarse.mesh.vertices().row(coarse.mesh.faces()(f, k));
    EXPECT_GT((centre / 3).norm(), 0.5 - 0.02) << "face " << f;
  }
  EXPECT_NEAR(volume_of(coarse.mesh), volume_of(fine), 0.03 * volume_of(fine));
}

TEST(SimplifyMesh, KeepsAMeshWithinTheBudgetAndChecksItsOptions) {
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 3);
  const SimplifiedMesh same = simplify_mesh(cube, {1000, 0.01});
  EXPECT_FALSE(same.changed);
  EXPECT_EQ(same.mesh.num_vertices(), cube.num_vertices());
  EXPECT_NE(error_of<ConfigError>([&] {
              simplify_mesh(cube, {3, 0.01});
            }).find("budget 3"),
            std::string::npos);
  EXPECT_NE(error_of<ConfigError>([&] {
              simplify_mesh(cube, {100, 0.0});
            }).find("tolerance"),
            std::string::npos);
}

TEST(SimplifyMesh, StopsAtTheToleranceAboveTheBudget) {
  // A cube's 26 surface vertices: collapsing any of its corners deforms it by far more than
  // 0.1 %, so the budget of 4 is not reached and the shape is kept.
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 3);
  const SimplifiedMesh kept = simplify_mesh(cube, {4, 0.001});
  EXPECT_GE(kept.mesh.num_vertices(), 8);
  EXPECT_NEAR(volume_of(kept.mesh), 1.0, 1e-9);
}

TEST(WrapMesh, ClosesAHoleNarrowerThanAlphaJustOutsideTheSurface) {
  if (!mesh_wrapping_available()) GTEST_SKIP() << "this build has no CGAL";
  // A sphere missing the fan around one pole: a hole about 0.2 m across.
  const TriangleMesh sphere = make_sphere(0.5, 16, 16);
  std::vector<int> kept;
  for (int f = 0; f < sphere.num_faces(); ++f) {
    bool at_pole = false;
    for (int k = 0; k < 3; ++k) at_pole |= sphere.vertices()(sphere.faces()(f, k), 2) > 0.49;
    if (!at_pole) kept.push_back(f);
  }
  ASSERT_LT(static_cast<int>(kept.size()), sphere.num_faces());
  const TriangleMesh holed("holed sphere", sphere.vertices(), sphere.faces()(kept, Eigen::all));
  ASSERT_FALSE(holed.is_closed());
  WrapOptions options;
  options.relative_alpha = 0.2;  // 0.35 m: wider than the hole
  options.relative_offset = 0.002;
  const TriangleMesh wrap = wrap_mesh(holed, options);
  EXPECT_TRUE(wrap.is_closed());
  const double offset = options.relative_offset * std::sqrt(3.0);
  const double radius = wrap.vertices().rowwise().norm().maxCoeff();
  EXPECT_NEAR(radius, 0.5 + offset, 2 * offset);
  EXPECT_NEAR(volume_of(wrap), volume_of(sphere), 0.05 * volume_of(sphere));
}

TEST(WrapMesh, GivesAnOpenBoxWallsAroundItsSurface) {
  if (!mesh_wrapping_available()) GTEST_SKIP() << "this build has no CGAL";
  // One side missing, a hole wider than alpha: the wrap follows both faces of the walls (a cup
  // stays a cup), a closed shell about twice the offset thick.
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 2);
  const TriangleMesh open("open box", cube.vertices(), cube.faces().topRows(cube.num_faces() - 8));
  const TriangleMesh wrap = wrap_mesh(open);
  EXPECT_TRUE(wrap.is_closed());
  const double offset = WrapOptions{}.relative_offset * std::sqrt(3.0);
  EXPECT_GT(volume_of(wrap), 5 * 2 * offset * 0.8);
  EXPECT_LT(volume_of(wrap), 0.5);
}

TEST(WrapMesh, ClosesNonManifoldSoups) {
  if (!mesh_wrapping_available()) GTEST_SKIP() << "this build has no CGAL";
  Points fin(5, 3);
  fin << 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0, -1, -1, 0;
  Triangles fins(3, 3);
  fins << 0, 1, 2, 0, 1, 3, 0, 1, 4;
  const TriangleMesh wrap = wrap_mesh(TriangleMesh("book", fin, fins));
  EXPECT_TRUE(wrap.is_closed());
  EXPECT_GT(volume_of(wrap), 0.0);
  EXPECT_NE(error_of<ConfigError>([&] {
              wrap_mesh(TriangleMesh("book", fin, fins), {0.0, 0.1});
            }).find("'book'"),
            std::string::npos);
}

}  // namespace
}  // namespace fignet
