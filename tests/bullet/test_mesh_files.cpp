#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "../temp_folder.h"
#include "fignet/bullet/convex_decomposition.h"
#include "fignet/bullet/mesh_file.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"

namespace fignet::bullet {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = "/usr/share/assimp/models";  // Debian's assimp-testmodels

using MeshFiles = testing::TempFolderTest;

// True when p lies outside the convex hull of `points` (adding it grows the hull).
bool outside_hull(const Points& points, const Vec3& p) {
  Points with(points.rows() + 1, 3);
  with << points, p.transpose();
  return convex_hull_volume(with) > convex_hull_volume(points) * (1 + 1e-9);
}

TEST_F(MeshFiles, EveryFormatLoadsAClosedBox) {
  const std::vector<fs::path> files = {kModels / "OBJ/box.obj", kModels / "OFF/Cube.off",
                                       kModels / "PLY/cube.ply", kModels / "PLY/cube_binary.ply",
                                       kModels / "glTF2/BoxTextured-glTF/BoxTextured.gltf"};
  for (const fs::path& file : files) {
    if (!fs::exists(file)) GTEST_SKIP() << "assimp-testmodels not installed";
    const TriangleMesh mesh = load_mesh_file(file);
    SCOPED_TRACE(file.string());
    // Exporters split corners by normal and texture coordinate; welding gives the 8 corners back.
    EXPECT_EQ(mesh.num_vertices(), 8);
    EXPECT_EQ(mesh.num_faces(), 12);
    EXPECT_TRUE(mesh.is_closed());
    const Vec3 extent = mesh.vertices().colwise().maxCoeff() - mesh.vertices().colwise().minCoeff();
    EXPECT_NEAR(compute_mass_properties(mesh).volume, extent.prod(), 1e-6 * extent.prod());
  }
}

TEST_F(MeshFiles, StlWrittenHereRoundTripsAProceduralShape) {
  const TriangleMesh cone = make_cone(0.5, 1.0);
  const fs::path path = dir_ / "cone.stl";
  std::ofstream out(path);
  out.precision(17);
  out << "solid cone\n";
  for (int f = 0; f < cone.num_faces(); ++f) {
    out << "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto v = cone.vertices().row(cone.faces()(f, k));
      out << "vertex " << v(0) << ' ' << v(1) << ' ' << v(2) << '\n';
    }
    out << "endloop\nendfacet\n";
  }
  out << "endsolid cone\n";
  out.close();
  const TriangleMesh loaded = load_mesh_file(path);
  EXPECT_EQ(loaded.num_vertices(), cone.num_vertices());
  EXPECT_TRUE(loaded.is_closed());
  EXPECT_NEAR(compute_mass_properties(loaded).volume, compute_mass_properties(cone).volume, 1e-5);
}

TEST_F(MeshFiles, InvalidFilesFailWithTheFileName) {
  if (!fs::exists(kModels / "invalid")) GTEST_SKIP() << "assimp-testmodels not installed";
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(kModels / "invalid")) {
    if (entry.path().extension() == ".txt") continue;
    try {
      load_mesh_file(entry.path());
      // A few "invalid" files are regression inputs assimp now reads; they must be valid meshes.
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(entry.path().string()), std::string::npos) << e.what();
    }
    ++checked;
  }
  EXPECT_GT(checked, 5);
  try {
    load_mesh_file(dir_ / "missing.obj");
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.obj': no such file"), std::string::npos);
  }
}

TEST_F(MeshFiles, FoldersListTheirMeshFilesSortedAndRejectEmptyOnes) {
  EXPECT_THROW(list_mesh_files(dir_), FileError);  // empty
  EXPECT_THROW(list_mesh_files(dir_ / "nope"), FileError);
  std::ofstream(dir_ / "notes.txt") << "not a mesh";
  EXPECT_THROW(list_mesh_files(dir_), FileError);
  write_obj(make_box(Vec3::Ones()), "b.obj");
  write_obj(make_box(Vec3::Ones()), "a.OBJ");
  const auto files = list_mesh_files(dir_);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].filename(), "a.OBJ");
  EXPECT_EQ(files[1].filename(), "b.obj");
}

TEST_F(MeshFiles, ConvexMeshesStayOneHullAndATorusKeepsItsHole) {
  EXPECT_TRUE(
      decompose_into_convex_parts(load_mesh_file(write_obj(make_sphere(1.0), "s.obj"))).empty());
  const TriangleMesh torus = load_mesh_file(write_obj(make_torus(0.7, 0.3), "torus.obj"));
  const auto parts = decompose_into_convex_parts(torus);
  ASSERT_GT(parts.size(), 4u);
  // The hole stays free: the centre and points of the axis are outside every piece, while the
  // single hull of the torus would contain them.
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(0.3, 0, 0), Vec3(0, -0.3, 0.1)}) {
    EXPECT_FALSE(outside_hull(torus.vertices(), p));
    for (const Points& part : parts) EXPECT_TRUE(outside_hull(part, p)) << p.transpose();
  }
  // The pieces cover the ring: their hulls add up to at least its volume, at most 25 % more.
  double sum = 0;
  for (const Points& part : parts) sum += convex_hull_volume(part);
  const double volume = compute_mass_properties(torus).volume;
  EXPECT_GT(sum, 0.98 * volume);
  EXPECT_LT(sum, 1.25 * volume);
}

}  // namespace
}  // namespace fignet::bullet
