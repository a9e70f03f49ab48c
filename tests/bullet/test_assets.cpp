#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "../error_text.h"
#include "../temp_folder.h"
#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/dataset_generator.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"

namespace fignet::bullet {
namespace {

using Assets = testing::TempFolderTest;

using testing::error_of;

// A horizontal peg (a 10 cm square bar along x, top at z = 2.05) through the hole of a torus
// (R = 0.7, r = 0.3) whose axis is along x. Hanging, the ring's inner surface rests on the peg:
// centre at 2.05 − (R − r) = 1.65. A convex hull would fill the hole and throw the torus off.
void expect_hangs_on_a_peg(BodySpec torus) {
  SceneSpec spec;
  spec.frames = 96;
  spec.floor = Floor{};
  BodySpec peg = make_body(make_box(Vec3(1.0, 0.05, 0.05), 1), 1.0, 0.5, 0.0);
  peg.kinematic = true;
  peg.pose.position = Vec3(0, 0, 2.0);
  torus.pose.orientation = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY());  // axis z -> x
  torus.pose.position = Vec3(0, 0, 1.7);
  spec.bodies = {peg, torus};
  const Trajectory t = BulletSimulation(spec).record();
  const Vec3 end = t.objects[1].poses.back().position;
  EXPECT_NEAR(end.z(), 1.65, 0.05) << "the torus fell off or rests on top of the peg";
  EXPECT_NEAR(end.y(), 0.0, 0.05);
}

TEST(NonConvexBodies, AProceduralTorusHangsOnAPeg) {
  BodySpec torus = make_body(make_movi_shape("torus"), 1.0, 0.5, 0.0, movi_convex_parts("torus"));
  ASSERT_EQ(torus.convex_parts.size(), 32u);
  expect_hangs_on_a_peg(torus);
}

TEST_F(Assets, ATorusFromAMeshFileHangsOnAPegThroughHacd) {
  BodySpec torus = load_body(write_obj(make_torus(0.7, 0.3), "torus.obj"), {1.0, {}, 0.5, 0.0});
  ASSERT_GT(torus.convex_parts.size(), 4u);
  expect_hangs_on_a_peg(torus);
}

TEST_F(Assets, LoadBodyTakesAMassOrADensity) {
  const auto path = write_obj(make_box(Vec3(0.5, 0.5, 0.5)), "cube.obj");  // 1 m³
  EXPECT_NEAR(load_body(path, {2.0, {}, 0.5, 0.1}).properties.mass, 2.0, 1e-9);
  EXPECT_NEAR(load_body(path, {2.0, 7.0, 0.5, 0.1}).properties.mass, 7.0, 1e-9);
  EXPECT_NEAR(load_body(path, {1.0, {}, 0.5, 0.1}, 2.0).properties.mass, 8.0, 1e-9);
  EXPECT_NE(error_of([&] {
              load_body(path, {1.0, -1.0, 0.5, 0.1});
            }).find("mass -1"),
            std::string::npos);
  // An open mesh (a box with a square hole, two of its 108 triangles missing) has no volume: the
  // convex hull's, or its surface's with shell inertia, or an error when the volume is asked
  // for. One warning says so.
  const TriangleMesh box = make_box(Vec3::Ones());
  Triangles open = box.faces().topRows(box.num_faces() - 2);
  const auto open_path = write_obj(TriangleMesh("open", box.vertices(), open), "open.obj");
  std::vector<std::string> warnings;
  MeshImportOptions options;
  options.warn = [&](const std::string& line) { warnings.push_back(line); };
  const BodySpec hull = load_body(open_path, {1.0, {}, 0.5, 0.1}, 1.0, options);
  EXPECT_NEAR(hull.properties.mass, 8.0, 1e-9);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("open.obj' (56 vertices): 4 open edges"), std::string::npos)
      << warnings[0];
  EXPECT_TRUE(hull.mesh->is_closed());  // FIGNet sees a closed surface
  options.inertia = MeshInertia::kShell;
  EXPECT_NEAR(load_body(open_path, {1.0, {}, 0.5, 0.1}, 1.0, options).properties.mass,
              24.0 - 4.0 / 9.0, 1e-7);
  options.inertia = MeshInertia::kVolume;
  EXPECT_NE(error_of([&] { load_body(open_path, {}, 1.0, options); }).find("open.obj': not closed"),
            std::string::npos);
}

TEST_F(Assets, MoviCDrawsOnlyTheFolderAtItsScalesAndMaterial) {
  write_obj(make_torus(0.7, 0.3), "ring.obj");
  write_obj(make_cone(0.5, 1.0), "cone.obj");
  MoviOptions options;
  options.preset = "movi-c";
  options.assets = dir_;
  std::set<std::string> names;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    for (const BodySpec& body : sample_scene(options, trajectory_seed(3, seed)).bodies) {
      names.insert(std::filesystem::path(body.mesh->name()).filename());
      EXPECT_EQ(body.properties.friction, 0.5);
      EXPECT_EQ(body.properties.restitution, 0.5);
      EXPECT_NEAR(body.properties.mass, compute_mass_properties(*body.mesh).volume, 1e-9);
      const Vec3 extent =
          body.mesh->vertices().colwise().maxCoeff() - body.mesh->vertices().colwise().minCoeff();
      // Largest side 1 m × U(0.75, 3.0); the principal frame may turn the box, so compare
      // with the bounding sphere's diameter bound as well.
      EXPECT_GE(extent.maxCoeff(), 0.75 - 1e-9);
      EXPECT_LE(extent.maxCoeff(), 3.0 * std::sqrt(3.0) + 1e-9);
    }
  }
  EXPECT_EQ(names, (std::set<std::string>{"ring.obj", "cone.obj"}));
  GenerateOptions generate;
  generate.scene = options;
  generate.scene.frames = 10;
  generate.count = 2;
  EXPECT_EQ(generate_dataset(generate).size(), 2u);
}

TEST_F(Assets, MoviBAddsTheFolderToItsShapes) {
  write_obj(make_cone(0.5, 1.0), "extra.obj");
  MoviOptions options;
  options.preset = "movi-b";
  options.assets = dir_;
  bool seen = false;
  for (std::uint64_t seed = 0; seed < 40 && !seen; ++seed) {
    for (const BodySpec& body : sample_scene(options, trajectory_seed(4, seed)).bodies)
      seen = seen || body.mesh->name().ends_with("extra.obj");
  }
  EXPECT_TRUE(seen);
}

TEST_F(Assets, BadFoldersAndPresetsFailClearly) {
  MoviOptions options;
  options.preset = "movi-c";
  EXPECT_NE(
      error_of([&] { sample_scene(options, 1); }).find("movi-c takes its objects from a folder"),
      std::string::npos);
  options.assets = dir_;
  EXPECT_NE(error_of([&] { sample_scene(options, 1); }).find("no mesh files"), std::string::npos);
  options.assets = dir_ / "missing";
  EXPECT_NE(error_of([&] { sample_scene(options, 1); }).find("not a readable folder"),
            std::string::npos);
  std::ofstream(dir_ / "broken.obj") << "f 1 2 3\n";
  options.assets = dir_;
  EXPECT_NE(error_of([&] { sample_scene(options, 1); }).find("broken.obj"), std::string::npos);
  options.preset = "movi-a";
  EXPECT_NE(error_of([&] { sample_scene(options, 1); }).find("assets need movi-b or movi-c"),
            std::string::npos);
}

}  // namespace
}  // namespace fignet::bullet
