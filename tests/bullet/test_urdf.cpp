// URDF files to bodies: geometry, merged inertia against hand-computed values, fixed and floating
// joints, contact coefficients, mesh URIs, and errors that name the file and the link or joint.
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <fstream>

#include "../error_text.h"
#include "../temp_folder.h"
#include "fignet/bullet/rigid_bodies.h"
#include "fignet/bullet/urdf.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"
#include "world_fixture.h"

namespace fignet::bullet {
namespace {

using testing::error_of;

class Urdf : public testing::TempFolderTest {
 protected:
  std::filesystem::path write_urdf(const std::string& body, const std::string& name = "r.urdf") {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path) << "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n" << body << "</robot>\n";
    return path;
  }
};

const char* kBoxLink = R"(
  <link name="box">
    <inertial><origin xyz="0 0 0"/><mass value="2"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/></inertial>
    <collision><geometry><box size="0.4 0.6 0.8"/></geometry></collision>
    <contact><lateral_friction value="0.7"/><restitution value="0.25"/></contact>
  </link>
)";

TEST_F(Urdf, ABoxLinkTakesItsInertialContactAndGeometry) {
  UrdfOptions options;
  options.base_pose.position = Vec3(1, 2, 3);
  const auto bodies = load_urdf(write_urdf(kBoxLink), options);
  ASSERT_EQ(bodies.size(), 1u);
  const BodySpec& body = bodies[0].body;
  EXPECT_EQ(bodies[0].name, "box");
  EXPECT_DOUBLE_EQ(body.properties.mass, 2.0);
  EXPECT_DOUBLE_EQ(body.properties.friction, 0.7);
  EXPECT_DOUBLE_EQ(body.properties.restitution, 0.25);
  EXPECT_TRUE(body.inertia.isApprox(Vec3(0.1, 0.2, 0.3), 1e-12));
  EXPECT_TRUE(body.pose.position.isApprox(Vec3(1, 2, 3), 1e-12));
  EXPECT_NEAR(compute_mass_properties(*body.mesh).volume, 0.4 * 0.6 * 0.8, 1e-12);
  EXPECT_FALSE(body.kinematic);
}

// Two 1 kg point masses 1 m either side of the centre (hand computation: Iyy = Izz = 2·1·1²),
// a box and a sphere joined by a fixed joint.
TEST_F(Urdf, FixedJointsMergeLinksByTheParallelAxisTheorem) {
  const auto bodies = load_urdf(write_urdf(R"(
  <link name="left">
    <inertial><origin xyz="-1 0 0"/><mass value="1"/>
      <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
    <collision><origin xyz="-1 0 0"/><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <link name="right">
    <inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>
    </inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="weld" type="fixed"><parent link="left"/><child link="right"/>
    <origin xyz="1 0 0"/></joint>
)"));
  ASSERT_EQ(bodies.size(), 1u);
  EXPECT_EQ(bodies[0].links, (std::vector<std::string>{"left", "right"}));
  const BodySpec& body = bodies[0].body;
  EXPECT_DOUBLE_EQ(body.properties.mass, 2.0);
  EXPECT_TRUE(body.pose.position.isZero(1e-12)) << body.pose.position.transpose();
  EXPECT_TRUE(body.inertia.isApprox(Vec3(0, 2, 2), 1e-12)) << body.inertia.transpose();
  EXPECT_EQ(body.convex_parts.size(), 2u);  // a box hull and a sphere hull
  // The mesh (in the body frame) spans both pieces: x from -1.1 (the box) to just under +1.1
  // (the sphere's polygonal equator).
  EXPECT_NEAR(body.mesh->vertices().col(0).minCoeff(), -1.1, 1e-9);
  EXPECT_NEAR(body.mesh->vertices().col(0).maxCoeff(), 1.1, 0.01);
}

TEST_F(Urdf, LinksWithoutInertialUseTheGeometryAtTheDefaultDensity) {
  UrdfOptions options;
  options.default_density = 500.0;
  options.default_friction = 0.3;
  const auto bodies = load_urdf(write_urdf(R"(
  <link name="c"><collision><origin xyz="0 0 0.5" rpy="1.5707963267948966 0 0"/>
    <geometry><cylinder radius="0.5" length="2"/></geometry></collision></link>
)"),
                                options);
  const BodySpec& body = bodies[0].body;
  const double volume = compute_mass_properties(make_cylinder(0.5, 1.0)).volume;
  EXPECT_NEAR(body.properties.mass, 500.0 * volume, 1e-9);
  EXPECT_DOUBLE_EQ(body.properties.friction, 0.3);
  EXPECT_TRUE(body.pose.position.isApprox(Vec3(0, 0, 0.5), 1e-9));
  // The cylinder's axis was turned from z to y: the longest extent is along world y.
  const Points world =
      (body.mesh->vertices() * body.pose.orientation.toRotationMatrix().transpose());
  EXPECT_NEAR(world.col(1).maxCoeff() - world.col(1).minCoeff(), 2.0, 1e-9);
}

TEST_F(Urdf, FloatingJointsSeparateBodiesAndZeroMassIsStatic) {
  const auto bodies = load_urdf(write_urdf(R"(
  <link name="table"><inertial><mass value="0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
    <collision><geometry><box size="2 2 0.1"/></geometry></collision></link>
)" + std::string(kBoxLink) + R"(
  <joint name="free" type="floating"><parent link="table"/><child link="box"/>
    <origin xyz="0 0 1"/></joint>
)"));
  ASSERT_EQ(bodies.size(), 2u);
  EXPECT_TRUE(bodies[0].body.kinematic);
  EXPECT_EQ(bodies[0].body.properties.mass, 0.0);
  EXPECT_EQ(bodies[1].name, "box");
  EXPECT_TRUE(bodies[1].body.pose.position.isApprox(Vec3(0, 0, 1), 1e-12));
}

TEST_F(Urdf, MeshesResolveRelativePackageAndScale) {
  std::filesystem::create_directories(dir_ / "my_pkg" / "meshes");
  std::filesystem::create_directories(dir_ / "my_pkg" / "urdf");
  const TriangleMesh cube = make_box(Vec3(0.5, 0.5, 0.5), 1);
  const auto mesh = write_obj(cube, "my_pkg/meshes/cube.obj");
  const char* link = R"(<link name="m"><collision><geometry>
    <mesh filename="%s" scale="1 2 3"/></geometry></collision></link>)";
  for (const std::string& uri : std::vector<std::string>{
           "../meshes/cube.obj", "package://my_pkg/meshes/cube.obj", "file://" + mesh.string()}) {
    char body[512];
    std::snprintf(body, sizeof body, link, uri.c_str());
    const auto bodies = load_urdf(write_urdf(body, "my_pkg/urdf/m.urdf"));
    EXPECT_NEAR(bodies[0].body.properties.mass, 1000.0 * 6.0, 1e-6) << uri;
  }
  UrdfOptions options;
  options.packages["elsewhere"] = dir_ / "my_pkg";
  char body[512];
  std::snprintf(body, sizeof body, link, "package://elsewhere/meshes/cube.obj");
  EXPECT_EQ(load_urdf(write_urdf(body), options).size(), 1u);
}

// An open mesh (a box with one side missing) in a link with <inertial>: the link takes its mass
// from the file and its collision piece is the closed surface around the mesh; one warning.
TEST_F(Urdf, AnOpenMeshLoadsThroughItsRepairedSurface) {
  const TriangleMesh box = make_box(Vec3(0.5, 0.5, 0.5), 2);
  write_obj(TriangleMesh("cup", box.vertices(), box.faces().topRows(box.num_faces() - 8)),
            "cup.obj");
  const auto path = write_urdf(R"(<link name="cup">
    <inertial><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><mesh filename="cup.obj"/></geometry></collision></link>)");
  std::vector<std::string> warnings;
  UrdfOptions options;
  options.mesh.warn = [&](const std::string& line) { warnings.push_back(line); };
  const auto bodies = load_urdf(path, options);
  ASSERT_EQ(bodies.size(), 1u);
  EXPECT_NEAR(bodies[0].body.properties.mass, 3.0, 1e-12);
  EXPECT_TRUE(bodies[0].body.mesh->is_closed());
  EXPECT_LE(bodies[0].body.mesh->num_vertices(), 1000);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("cup.obj"), std::string::npos);
  EXPECT_NE(warnings[0].find("open edges"), std::string::npos);
}

TEST_F(Urdf, ErrorsNameTheFileAndTheCulprit) {
  EXPECT_NE(error_of([&] { load_urdf(dir_ / "missing.urdf"); }).find("cannot be opened"),
            std::string::npos);
  const std::string invalid = error_of([&] { load_urdf(write_urdf("<link>", "bad.urdf")); });
  EXPECT_NE(invalid.find("bad.urdf': not a valid URDF ("), std::string::npos) << invalid;
  const std::string hinge = error_of([&] {
    load_urdf(write_urdf(std::string(kBoxLink) + R"(<link name="lid">
      <collision><geometry><box size="1 1 1"/></geometry></collision></link>
      <joint name="hinge" type="revolute"><parent link="box"/><child link="lid"/>
      <axis xyz="0 0 1"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>)"));
  });
  EXPECT_NE(hinge.find("joint 'hinge' is revolute"), std::string::npos) << hinge;
  const std::string ghost = error_of([&] { load_urdf(write_urdf(R"(<link name="ghost"/>)")); });
  EXPECT_NE(ghost.find("link 'ghost': no collision geometry"), std::string::npos) << ghost;
  const std::string no_file = error_of([&] {
    load_urdf(write_urdf(R"(<link name="m"><collision><geometry>
      <mesh filename="nowhere.obj"/></geometry></collision></link>)"));
  });
  EXPECT_NE(no_file.find("link 'm': "), std::string::npos) << no_file;
  EXPECT_NE(no_file.find("nowhere.obj"), std::string::npos) << no_file;
  const std::string flat = error_of([&] {
    load_urdf(write_urdf(R"(<link name="f"><collision><geometry>
      <box size="1 0 1"/></geometry></collision></link>)"));
  });
  EXPECT_NE(flat.find("link 'f': box size y 0"), std::string::npos) << flat;
  const std::string package = error_of([&] {
    load_urdf(write_urdf(R"(<link name="p"><collision><geometry>
      <mesh filename="package://nope/a.obj"/></geometry></collision></link>)"));
  });
  EXPECT_NE(package.find("package 'nope'"), std::string::npos) << package;
}

// The same URDF body in native Bullet rests on the floor at its half height; in a FIGNet world
// with exact free fall it follows the ballistic formula.
TEST_F(Urdf, BodiesWorkInEitherWorld) {
  UrdfOptions options;
  options.base_pose.position = Vec3(0, 0, 1);
  const BodySpec spec = load_urdf(write_urdf(kBoxLink), options)[0].body;
  {
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
    world.setGravity(btVector3(0, 0, -10));
    RigidBodies bodies(world);
    bodies.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0, btVector3(0, 0, 0),
               btTransform::getIdentity());
    btRigidBody* box = bodies.add(spec, 0.0);
    for (int i = 0; i < 480; ++i) world.stepSimulation(1.0f / 240, 0, 1.0f / 240);
    EXPECT_NEAR(box->getCenterOfMassPosition().z(), 0.4, 0.01);
  }
  testing::WorldFixture fixture(testing::recording_predictor());
  RigidBodies bodies(fixture.world);
  btRigidBody* box = bodies.add(spec);
  fixture.step(10);
  // Released in free flight, seeded on its parabola: z_n = z_0 - g·dt²·n²/2.
  const double dt = testing::WorldFixture::kStep;
  EXPECT_NEAR(box->getCenterOfMassPosition().z(), 1.0 - 10.0 * dt * dt * 50.0, 1e-5);
}

}  // namespace
}  // namespace fignet::bullet
