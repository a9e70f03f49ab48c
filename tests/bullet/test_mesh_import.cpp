// Meshes as people have them become bodies: messy files load with one warning, the graph's node
// budget holds while Bullet keeps the full shape, and MOVi-C runs on a folder of such meshes.
#include <gtest/gtest.h>

#include <btBulletDynamicsCommon.h>

#include <set>

#include "../error_text.h"
#include "../temp_folder.h"
#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/conversions.h"
#include "fignet/bullet/dataset_generator.h"
#include "fignet/bullet/shape_mesh.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"

namespace fignet::bullet {
namespace {

using MeshImport = testing::TempFolderTest;
using testing::error_of;

// Options that collect warnings instead of printing them.
MeshImportOptions collecting(std::vector<std::string>& warnings) {
  MeshImportOptions options;
  options.warn = [&warnings](const std::string& line) { warnings.push_back(line); };
  return options;
}

TEST(MeshInertiaNames, RoundTripAndListTheChoices) {
  for (MeshInertia mode :
       {MeshInertia::kAuto, MeshInertia::kVolume, MeshInertia::kConvexHull, MeshInertia::kShell}) {
    EXPECT_EQ(parse_mesh_inertia(mesh_inertia_name(mode)), mode);
  }
  EXPECT_NE(error_of([] { parse_mesh_inertia("solid"); }).find("expected auto, volume"),
            std::string::npos);
}

TEST(ImportMesh, ACleanMeshNeedsNothingAndSaysNothing) {
  std::vector<std::string> warnings;
  const TriangleMesh torus = make_torus(0.7, 0.3);
  const ImportedMesh imported = import_mesh(torus, collecting(warnings));
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(imported.surface.num_vertices(), torus.num_vertices());
  EXPECT_FALSE(imported.simplified());
  EXPECT_GT(imported.convex_parts.size(), 4u);  // HACD, as before
  const UnitInertia unit = mesh_inertia(imported, MeshInertia::kAuto);
  EXPECT_NEAR(unit.mass, compute_mass_properties(torus).volume, 1e-12);
}

TEST(ImportMesh, AFineSphereIsSimplifiedForTheGraphButCollidesAtFullResolution) {
  std::vector<std::string> warnings;
  const TriangleMesh fine = make_sphere(0.5, 140, 143);
  const ImportedMesh imported = import_mesh(fine, collecting(warnings));
  EXPECT_LE(imported.surface.num_vertices(), 1000);
  EXPECT_TRUE(imported.surface.is_closed());
  EXPECT_TRUE(imported.simplified());
  EXPECT_LE(imported.simplification_error, 0.01 * 1.0);
  ASSERT_EQ(imported.convex_parts.size(), 1u);
  EXPECT_EQ(imported.convex_parts[0].rows(), fine.num_vertices());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("from " + std::to_string(fine.num_vertices()) + " to"),
            std::string::npos)
      << warnings[0];
  // Mass comes from the full mesh, not the simplified one.
  const BodySpec body = make_body(fine, BodyMaterial{1000.0, {}, 0.5, 0.0});
  EXPECT_NEAR(body.properties.mass, 1000.0 * compute_mass_properties(fine).volume, 1e-9);
  EXPECT_LE(body.mesh->num_vertices(), 1000);
  ASSERT_EQ(body.convex_parts.size(), 1u);
  EXPECT_EQ(body.convex_parts[0].rows(), fine.num_vertices());
  // No budget: the mesh as it is.
  MeshImportOptions unlimited = collecting(warnings);
  unlimited.max_graph_vertices = 0;
  EXPECT_EQ(import_mesh(fine, unlimited).surface.num_vertices(), fine.num_vertices());
  unlimited.max_graph_vertices = 2;
  EXPECT_NE(error_of([&] { import_mesh(fine, unlimited); }).find("budget 2"), std::string::npos);
}

TEST(ImportMesh, ASoupWithFlippedShellsBecomesTheClosedMesh) {
  // Two cubes in one file, every corner written per face, the second inside out.
  const TriangleMesh cube = make_box(Vec3::Constant(0.5), 1);
  Points vertices(2 * 3 * cube.num_faces(), 3);
  Triangles faces(2 * cube.num_faces(), 3);
  for (int copy = 0; copy < 2; ++copy) {
    for (int f = 0; f < cube.num_faces(); ++f) {
      const int row = copy * cube.num_faces() + f;
      for (int k = 0; k < 3; ++k) {
        vertices.row(3 * row + k) = cube.vertices().row(cube.faces()(f, copy ? 2 - k : k));
        vertices(3 * row + k, 0) += 2.0 * copy;
      }
      faces.row(row) << 3 * row, 3 * row + 1, 3 * row + 2;
    }
  }
  std::vector<std::string> warnings;
  const ImportedMesh imported =
      import_mesh(TriangleMesh("pair.stl", vertices, faces), collecting(warnings));
  EXPECT_TRUE(imported.repair.empty());  // closed once welded and turned outward
  EXPECT_TRUE(imported.surface.is_closed());
  EXPECT_EQ(imported.defects.shells, 2);
  EXPECT_EQ(imported.defects.inverted_shells, 1);
  EXPECT_NEAR(mesh_inertia(imported, MeshInertia::kVolume).mass, 2.0, 1e-12);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("mesh 'pair.stl' (72 vertices): 2 shells"), std::string::npos)
      << warnings[0];
}

TEST(ImportMesh, AnOpenMeshIsWrappedOrHulledAndWeighedByTheChosenMode) {
  const TriangleMesh box = make_box(Vec3::Constant(0.5), 2);
  const TriangleMesh open("cup", box.vertices(), box.faces().topRows(box.num_faces() - 8));
  std::vector<std::string> warnings;
  const ImportedMesh imported = import_mesh(open, collecting(warnings));
  EXPECT_TRUE(imported.surface.is_closed());
  EXPECT_EQ(imported.repair, mesh_wrapping_available() ? "alpha wrap" : "convex hull");
  EXPECT_LE(imported.surface.num_vertices(), 1000);
  // HACD cannot split the wrap's thin walls: Bullet collides the cup's hull, one piece.
  ASSERT_EQ(imported.convex_parts.size(), 1u);
  EXPECT_EQ(imported.convex_parts[0].rows(), imported.cleaned.num_vertices());
  EXPECT_EQ(imported.hull_collision, mesh_wrapping_available());
  EXPECT_NEAR(mesh_inertia(imported, MeshInertia::kAuto).mass, 1.0, 1e-9);  // the hull
  EXPECT_NEAR(mesh_inertia(imported, MeshInertia::kConvexHull).mass, 1.0, 1e-9);
  const UnitInertia shell = mesh_inertia(imported, MeshInertia::kShell);
  EXPECT_NEAR(shell.mass, 5.0, 1e-9);  // five 1 m² sides
  EXPECT_EQ(shell.mass_scale_power, 2);
  EXPECT_LT(shell.center_of_mass.z(), 0.0);  // the open side is the top: weight sits low
  EXPECT_NE(error_of([&] { mesh_inertia(imported, MeshInertia::kVolume); }).find("not closed"),
            std::string::npos);
  // Without repair the graph sees the open surface itself.
  MeshImportOptions as_is = collecting(warnings);
  as_is.repair = false;
  EXPECT_FALSE(import_mesh(open, as_is).surface.is_closed());
}

TEST(ShapeMeshCache, HandsOutMeshesWithinItsBudget) {
  const TriangleMesh fine = make_sphere(0.5, 140, 143);
  btSphereShape shape(0.5);
  ShapeMeshCache limited({500, 0.01});
  limited.set_mesh(shape, std::make_shared<const TriangleMesh>(fine));
  EXPECT_LE(limited.mesh_of(shape)->num_vertices(), 500);
  EXPECT_TRUE(limited.mesh_of(shape)->is_closed());
  ShapeMeshCache unlimited;
  unlimited.set_mesh(shape, std::make_shared<const TriangleMesh>(fine));
  EXPECT_EQ(unlimited.mesh_of(shape)->num_vertices(), fine.num_vertices());
}

TEST_F(MeshImport, MoviCRunsOnAFolderOfMessyMeshesWarningOncePerFile) {
  const TriangleMesh box = make_box(Vec3::Constant(0.5), 2);
  write_obj(TriangleMesh("open", box.vertices(), box.faces().topRows(box.num_faces() - 8)),
            "open.obj");
  Triangles flipped = box.faces();
  for (int f = 0; f < flipped.rows(); f += 3) std::swap(flipped(f, 1), flipped(f, 2));
  write_obj(TriangleMesh("flipped", box.vertices(), flipped), "flipped.obj");
  write_obj(make_sphere(0.5, 60, 60), "fine.obj");
  GenerateOptions options;
  options.scene.preset = "movi-c";
  options.scene.assets = dir_;
  options.scene.frames = 24;
  options.count = 4;
  options.threads = 1;
  std::vector<std::string> warnings;
  options.scene.mesh_import = collecting(warnings);
  options.scene.mesh_import.max_graph_vertices = 400;
  const std::vector<Trajectory> data = generate_dataset(options);
  ASSERT_EQ(data.size(), 4u);
  std::set<std::string> files;
  for (const std::string& line : warnings) files.insert(line.substr(0, line.find("':")));
  EXPECT_EQ(warnings.size(), 3u);  // each file needed something, and said so once
  EXPECT_EQ(files.size(), 3u);
  for (const Trajectory& t : data) {
    for (const TrajectoryObject& object : t.objects) {
      EXPECT_TRUE(object.mesh->is_closed()) << object.mesh->name();
      EXPECT_LE(object.mesh->num_vertices(), 400) << object.mesh->name();
      for (const Pose& pose : object.poses) ASSERT_TRUE(pose.position.allFinite());
      // Nothing falls through the floor: Bullet collides the bodies it was given.
      EXPECT_GT(posed_vertices(*object.mesh, object.poses.back()).col(2).minCoeff(), -0.05);
    }
  }
}

}  // namespace
}  // namespace fignet::bullet
