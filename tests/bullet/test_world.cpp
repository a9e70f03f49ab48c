#include <gtest/gtest.h>

#include <fmt/format.h>

#include <set>

#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/dataset_generator.h"
#include "fignet/bullet/shape_mesh.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/geometry/shapes.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/rollout/rollout.h"
#include "fignet/train/trainer.h"
#include "world_fixture.h"

namespace fignet::bullet {
namespace {

using testing::at;
using testing::recording_predictor;
using testing::WorldFixture;

// Free flight, by the world's own path and by an exact-gravity predictor through the network's
// path: both follow x_{n+1} = 2x_n − x_{n−1} + g·dt². A body seeded in free flight has the
// parabola through its start as its history, so it stays on it: x_n = x_0 + n·dt·v0 + n²/2·g·dt²,
// and its velocity (the last step's) is v0 + (n − ½)·g·dt. Seeded moving straight
// (seed_falling off) it follows Bullet's semi-implicit Euler instead: x_n = x_0 + n·dt·v0 +
// n(n+1)/2·g·dt², v_n = v0 + n·g·dt, ½·g·dt² lower at every step.
TEST(FIGNetWorld, FreeFlightFollowsTheAnalyticTrajectory) {
  for (const bool seed_falling : {true, false}) {
    for (const bool free_flight : {true, false}) {
      SCOPED_TRACE(fmt::format("{}, seeded {}",
                               free_flight ? "free-flight path" : "through the predictor",
                               seed_falling ? "falling" : "straight"));
      FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
      options.free_flight = free_flight;
      options.seed_falling = seed_falling;
      auto predictor = recording_predictor();
      const auto* recorder = predictor.get();
      WorldFixture fixture(std::move(predictor), {}, options);
      // Without Bullet's one-step latency, motion states show the step's own result.
      fixture.world.setLatencyMotionStateInterpolation(false);
      btRigidBody* box = fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.3f, 0.4f)), 2.0,
                                     at(Vec3(0, 0, 50)));
      const Vec3 v0(1.0, -2.0, 3.0), w0(0.5, -1.0, 2.0);
      box->setLinearVelocity(to_bt(v0));
      box->setAngularVelocity(to_bt(w0));
      const double dt = WorldFixture::kStep;
      const Vec3 g(0, 0, -10);
      double worst_precise = 0;
      for (int n = 1; n <= 48; ++n) {
        fixture.step();
        const double fall = seed_falling ? 0.5 * n * n : 0.5 * n * (n + 1);
        const Vec3 expected = Vec3(0, 0, 50) + n * dt * v0 + fall * dt * dt * g;
        const Vec3 position = from_bt(box->getCenterOfMassPosition());
        ASSERT_LT((position - expected).norm(), 2e-4 * (1 + n)) << "step " << n;
        worst_precise =
            std::max(worst_precise, (fixture.world.precise_pose(*box).position - expected).norm());
        const double speed_steps = seed_falling ? n - 0.5 : n;
        EXPECT_LT((from_bt(box->getLinearVelocity()) - (v0 + speed_steps * dt * g)).norm(), 1e-3);
        btTransform motion;
        box->getMotionState()->getWorldTransform(motion);
        EXPECT_LT((motion.getOrigin() - box->getWorldTransform().getOrigin()).length(), 1e-5);
      }
      // The world's own path is exact in double precision; the predictor's goes through vertex
      // accelerations and a rigid fit.
      if (free_flight) {
        EXPECT_LT(worst_precise, 1e-9);
        // Constant angular velocity: 48 steps turn the box by 48·dt·|ω| about ω.
        const Eigen::AngleAxisd turned(fixture.world.precise_pose(*box).orientation);
        EXPECT_NEAR(turned.angle(), 48 * dt * w0.norm(), 1e-9);
        EXPECT_LT((turned.axis() - w0.normalized()).norm(), 1e-9);
        EXPECT_EQ(recorder->calls, 0);
      }
      const FIGNetStepStats& stats = fixture.world.last_step_stats();
      EXPECT_EQ(stats.simulated_bodies, free_flight ? 0 : 1);
      EXPECT_EQ(stats.free_flight_bodies, free_flight ? 1 : 0);
    }
  }
}

// Bodies seeded where something may hold them move straight in their history: one placed at
// rest on the floor (a parabola would show it as having dropped onto it at g·dt/2 a moment ago)
// and two released 5 cm apart in the air (within d_c of each other). A body alone in the air,
// whose broadphase box still overlaps a tilted neighbour's, falls along its parabola.
TEST(FIGNetWorld, OnlyBodiesInFreeFlightAreSeededFalling) {
  auto predictor = recording_predictor();
  auto* recorder = predictor.get();
  WorldFixture fixture(std::move(predictor), {}, FIGNetWorldOptions::network_alone());
  fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  auto cube = [] { return std::make_unique<btBoxShape>(btVector3(0.5f, 0.5f, 0.5f)); };
  fixture.add(cube(), 1.0, at(Vec3(0, 0, 0.52)));  // on the floor
  fixture.add(cube(), 1.0, at(Vec3(3, 0, 2.0)));   // a pair in the air, 5 cm apart
  fixture.add(cube(), 1.0, at(Vec3(3, 1.05, 2.0)));
  // Alone, with a neighbour turned 45° about x and z 1.25 m off along each axis: their
  // broadphase boxes overlap (0.55 + 0.90 m reach in x and y, 0.55 + 0.76 in z), their bounding
  // spheres (0.87 m) stay 0.33 m apart beyond d_c.
  const Eigen::Quaterniond tilted =
      Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()) * Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX());
  btRigidBody* alone = fixture.add(cube(), 1.0, at(Vec3(-6, 0, 3.0)));
  btRigidBody* neighbour = fixture.add(cube(), 1.0, at(Vec3(-4.75, 1.25, 4.25), tilted));
  fixture.step();
  ASSERT_EQ(recorder->last_scene.objects.size(), 5u);
  bool paired = false;
  btBroadphasePairArray& pairs = fixture.world.getPairCache()->getOverlappingPairArray();
  for (int i = 0; i < pairs.size(); ++i) {
    const void* a = pairs[i].m_pProxy0->m_clientObject;
    const void* b = pairs[i].m_pProxy1->m_clientObject;
    paired = paired || (a == alone && b == neighbour) || (a == neighbour && b == alone);
  }
  ASSERT_TRUE(paired) << "the test needs the two boxes' broadphase boxes to overlap";
  // The history the predictor saw (τ ≤ 0 the time before the step): the falling boxes' centres
  // on z(τ) = z₀ − 5τ², released at rest at the parabola's top; the others' all equal.
  const double dt = WorldFixture::kStep;
  int falling = 0;
  for (const SceneObject& object : recorder->last_scene.objects) {
    const Vec3 start = object.centers.row(2).transpose();
    const auto z = [&](int k) { return object.centers(k, 2); };
    SCOPED_TRACE(fmt::format("box at ({}, {}, {})", start.x(), start.y(), start.z()));
    if (start.x() < -1.0) {
      ++falling;
      EXPECT_NEAR(z(2) - z(1), 5.0 * dt * dt, 1e-9);
      EXPECT_NEAR(z(2) - z(0), 5.0 * 4 * dt * dt, 1e-9);
    } else {
      EXPECT_EQ(z(0), z(2));
      EXPECT_EQ(z(1), z(2));
    }
  }
  EXPECT_EQ(falling, 2);
}

TEST(FIGNetWorld, AKinematicBodyFollowsItsMotionStateExactly) {
  auto predictor = recording_predictor();
  auto* recorder = predictor.get();
  WorldFixture fixture(std::move(predictor));
  btRigidBody* pusher = fixture.add(std::make_unique<btBoxShape>(btVector3(0.1f, 0.1f, 0.1f)), 0.0,
                                    at(Vec3(0, 0, 1)));
  pusher->setCollisionFlags(pusher->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  pusher->setActivationState(DISABLE_DEACTIVATION);
  btRigidBody* ball = fixture.add(std::make_unique<btSphereShape>(0.1f), 1.0, at(Vec3(0.25, 0, 1)));
  (void)ball;
  for (int n = 1; n <= 10; ++n) {
    const btTransform target(btQuaternion(btVector3(0, 0, 1), 0.1f * n),
                             btVector3(0.01f * n, 0, 1));
    pusher->getMotionState()->setWorldTransform(target);
    fixture.step();
    EXPECT_EQ(pusher->getWorldTransform().getOrigin(), target.getOrigin());
    // The graph saw the pusher's next pose as this target.
    ASSERT_EQ(recorder->last_scene.objects.size(), 2u);
    const SceneObject& kinematic = recorder->last_scene.objects[1];
    ASSERT_TRUE(kinematic.kinematic);
    EXPECT_NEAR(kinematic.next_center.x(), 0.01 * n, 1e-6);
  }
}

TEST(FIGNetWorld, BroadphaseFacePairsEqualAllPairsBruteForce) {
  auto predictor = recording_predictor();
  auto* recorder = predictor.get();
  WorldFixture fixture(std::move(predictor));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 25; ++i) {
    std::unique_ptr<btCollisionShape> shape;
    if (i % 3 == 0) shape = std::make_unique<btBoxShape>(btVector3(0.15f, 0.1f, 0.2f));
    if (i % 3 == 1) shape = std::make_unique<btSphereShape>(0.15f);
    if (i % 3 == 2) shape = std::make_unique<btCylinderShapeZ>(btVector3(0.1f, 0.1f, 0.2f));
    const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    fixture.add(std::move(shape), 1.0, at(Vec3(u(rng), u(rng), 0.3 + 0.5 * (u(rng) + 1)), q));
  }
  auto floor = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0.0f);
  fixture.add(std::move(floor), 0.0, at(Vec3::Zero()));
  for (int step = 0; step < 3; ++step) {
    fixture.step();
    GraphBuilder broadphase_builder({}), brute_force_builder({});
    Graph graph;
    broadphase_builder.build_with_candidates(recorder->last_scene, recorder->last_candidates,
                                             graph);
    brute_force_builder.build(recorder->last_scene, graph);
    auto key = [](const FacePair& p) {
      return std::tuple(p.object_a, p.face_a, p.object_b, p.face_b);
    };
    std::set<std::tuple<int, int, int, int>> a, b;
    for (const FacePair& p : broadphase_builder.face_pairs()) a.insert(key(p));
    for (const FacePair& p : brute_force_builder.face_pairs()) b.insert(key(p));
    EXPECT_EQ(a, b);
    EXPECT_GT(a.size(), 10u);
  }
}

TEST(ShapeMeshes, EachShapeTypeHasItsVolumeAndExtent) {
  struct Case {
    std::unique_ptr<btCollisionShape> shape;
    double volume;
    Vec3 extent;
    double volume_tolerance = 0.05;  // polygons lose a little of a round shape's volume
  };
  const double pi = M_PI;
  std::vector<Case> cases;
  cases.push_back({std::make_unique<btBoxShape>(btVector3(0.5f, 1.0f, 1.5f)), 6.0, Vec3(1, 2, 3)});
  // Spheres keep MOVi's 64 vertices (what the model was trained on): 13 % under the true volume.
  cases.push_back({std::make_unique<btSphereShape>(1.0f), 4.0 / 3.0 * pi, Vec3(2, 2, 2), 0.15});
  cases.push_back({std::make_unique<btCylinderShape>(btVector3(0.5f, 1.0f, 0.5f)), pi * 0.25 * 2.0,
                   Vec3(1, 2, 1)});
  cases.push_back({std::make_unique<btCylinderShapeX>(btVector3(1.0f, 0.5f, 0.5f)), pi * 0.25 * 2.0,
                   Vec3(2, 1, 1)});
  cases.push_back({std::make_unique<btCylinderShapeZ>(btVector3(0.5f, 0.5f, 1.0f)), pi * 0.25 * 2.0,
                   Vec3(1, 1, 2)});
  cases.push_back(
      {std::make_unique<btConeShapeZ>(0.5f, 2.0f), pi * 0.25 * 2.0 / 3.0, Vec3(1, 1, 2)});
  cases.push_back({std::make_unique<btCapsuleShape>(0.5f, 1.0f),
                   pi * 0.25 * 1.0 + 4.0 / 3.0 * pi * 0.125, Vec3(1, 2, 1)});
  auto hull = std::make_unique<btConvexHullShape>();
  for (int i = 0; i < 8; ++i)
    hull->addPoint(btVector3(i & 1 ? 1.0f : 0.0f, i & 2 ? 1.0f : 0.0f, i & 4 ? 1.0f : 0.0f));
  cases.push_back({std::move(hull), 1.0, Vec3(1, 1, 1)});
  auto scaled = std::make_unique<btBoxShape>(btVector3(0.5f, 0.5f, 0.5f));
  scaled->setLocalScaling(btVector3(2, 1, 1));
  cases.push_back({std::move(scaled), 2.0, Vec3(2, 1, 1)});
  for (auto& c : cases) {
    SCOPED_TRACE(c.shape->getName());
    const TriangleMesh mesh = shape_to_mesh(*c.shape);
    EXPECT_TRUE(mesh.is_closed());
    EXPECT_NEAR(compute_mass_properties(mesh).volume, c.volume, c.volume_tolerance * c.volume);
    const Vec3 extent = mesh.vertices().colwise().maxCoeff() - mesh.vertices().colwise().minCoeff();
    EXPECT_LT((extent - c.extent).cwiseAbs().maxCoeff(), 0.02 * c.extent.maxCoeff());
  }
  // A compound of two unit boxes side by side.
  btBoxShape unit(btVector3(0.5f, 0.5f, 0.5f));
  btCompoundShape compound;
  compound.addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(-0.5f, 0, 0)), &unit);
  compound.addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0.5f, 0, 0)), &unit);
  const TriangleMesh mesh = shape_to_mesh(compound);
  EXPECT_NEAR(compute_mass_properties(mesh).volume, 2.0, 1e-9);
  EXPECT_NEAR(mesh.vertices().col(0).maxCoeff() - mesh.vertices().col(0).minCoeff(), 2.0, 1e-6);
}

TEST(ShapeMeshes, UnsupportedShapesNameThemselves) {
  btEmptyShape empty;
  try {
    shape_to_mesh(empty);
    ADD_FAILURE() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'Empty'"), std::string::npos) << e.what();
  }
}

// A mesh registered for a shape replaces the conversion; one in another frame or scale is refused.
TEST(FIGNetWorld, ShapeMeshesCanBeGivenAndMustFitTheShape) {
  auto predictor = recording_predictor();
  testing::RecordingPredictor& recorder = *predictor;
  WorldFixture fixture(std::move(predictor), {}, FIGNetWorldOptions::network_alone());
  auto shape = std::make_unique<btBoxShape>(btVector3(0.5, 0.5, 0.5));
  const btCollisionShape& box = *shape;
  Pose pose;
  pose.position = Vec3(0, 0, 5);
  fixture.add(std::move(shape), 1.0, pose);
  fixture.step();
  const int converted = recorder.last_scene.objects.at(0).mesh->num_vertices();
  auto cube = std::make_shared<const TriangleMesh>(make_box(Vec3(0.5, 0.5, 0.5), 1));
  ASSERT_NE(converted, cube->num_vertices());
  fixture.world.set_shape_mesh(box, cube);
  fixture.step();
  EXPECT_EQ(recorder.last_scene.objects.at(0).mesh->num_vertices(), cube->num_vertices());
  auto twice = std::make_shared<const TriangleMesh>(make_box(Vec3(1.0, 1.0, 1.0), 1));
  EXPECT_THROW(fixture.world.set_shape_mesh(box, twice), ConfigError);
}

// At 50 m/s a step is 1 m, ten collision radii: without the guard a body that the predictor does
// not stop passes through the floor between two steps; with it, the step ends on the floor.
TEST(FIGNetWorld, TheSweepGuardStopsTunnellingThroughTheFloor) {
  for (bool guard : {true, false}) {
    FIGNetWorldOptions options;
    options.sweep_guard = guard;
    options.penetration_guard = false;
    WorldFixture fixture(recording_predictor(), {}, options);
    fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
    Pose start;
    start.position = Vec3(0, 0, 3);
    btRigidBody* box =
        fixture.add(std::make_unique<btBoxShape>(btVector3(0.5, 0.5, 0.5)), 1.0, start);
    box->setLinearVelocity(btVector3(0, 0, -50));
    double lowest_centre = 3.0;
    int guarded = 0;
    for (int step = 0; step < 3; ++step) {
      fixture.step();
      lowest_centre = std::min(lowest_centre, double(box->getCenterOfMassPosition().z()));
      guarded += fixture.world.last_step_stats().guarded_bodies;
    }
    if (guard) {
      EXPECT_GE(lowest_centre, 0.5 - 0.02) << "the box went into the floor";
      EXPECT_EQ(guarded, 1);
    } else {
      EXPECT_LT(lowest_centre, 0.0) << "without the guard the box should have passed through";
    }
  }
}

// A MOVi body thrown at 6 m/s moves 0.125 m a frame, more than d_c: at such speeds impacts are
// in the training data, and the network decides them. The guard must leave a step that ends a few
// centimetres into the surface it hits (a predictor that ignores contact here) as predicted; it
// once stopped every such body dead where it first touched, taking its velocity at each impact.
TEST(FIGNetWorld, TheSweepGuardLeavesImpactsAtTrainingSpeedsToTheNetwork) {
  FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
  ASSERT_TRUE(options.sweep_guard);
  WorldFixture fixture(recording_predictor(), {}, options);
  fixture.world.setLatencyMotionStateInterpolation(false);
  fixture.add(std::make_unique<btBoxShape>(btVector3(0.5, 0.5, 0.5)), 0.0, at(Vec3(1.0, 0, 5)));
  // The faces 5 cm apart, the thrown cube closing at 6 m/s, no gravity across the gap's axis.
  btRigidBody* cube = fixture.add(std::make_unique<btBoxShape>(btVector3(0.3, 0.3, 0.3)), 1.0,
                                  at(Vec3(0.15, 0, 5)));
  cube->setLinearVelocity(btVector3(6, 0, 0));
  const double x0 = cube->getCenterOfMassPosition().x();
  fixture.step();
  EXPECT_EQ(fixture.world.last_step_stats().guarded_bodies, 0);
  EXPECT_NEAR(cube->getCenterOfMassPosition().x() - x0, 6.0 * WorldFixture::kStep, 1e-5);
  EXPECT_NEAR(cube->getLinearVelocity().x(), 6.0, 1e-4);
}

// A guarded body stops on the surface its core would have crossed and keeps its velocity along
// it: 50 m/s down and 5 m/s sideways onto the floor leave 5 m/s sideways, in Bullet's velocity and
// in the history the next prediction reads.
TEST(FIGNetWorld, TheSweepGuardKeepsTheVelocityAlongTheSurface) {
  FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
  auto predictor = recording_predictor();
  auto* recorder = predictor.get();
  WorldFixture fixture(std::move(predictor), {}, options);
  fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  btRigidBody* box =
      fixture.add(std::make_unique<btBoxShape>(btVector3(0.5, 0.5, 0.5)), 1.0, at(Vec3(0, 0, 1.2)));
  box->setLinearVelocity(btVector3(5, 0, -50));
  fixture.step();
  ASSERT_EQ(fixture.world.last_step_stats().guarded_bodies, 1);
  EXPECT_NEAR(box->getCenterOfMassPosition().z(), 0.5, 0.02) << "stops where it touches";
  EXPECT_NEAR(box->getLinearVelocity().x(), 5.0, 1e-3);
  EXPECT_NEAR(box->getLinearVelocity().z(), 0.0, 1e-3);
  fixture.step();
  const SceneObject& seen = recorder->last_scene.objects.at(0);
  const Vec3 velocity =
      (seen.centers.row(seen.centers.rows() - 1) - seen.centers.row(seen.centers.rows() - 2))
          .transpose() /
      WorldFixture::kStep;
  EXPECT_NEAR(velocity.x(), 5.0, 1e-3);
  EXPECT_NEAR(velocity.z(), 0.0, 1e-3);
}

TEST(FIGNetWorld, RejectsAnotherTimeStepOrGravity) {
  WorldFixture fixture(recording_predictor());
  fixture.add(std::make_unique<btSphereShape>(0.1f), 1.0, at(Vec3(0, 0, 1)));
  try {
    fixture.world.stepSimulation(1.0f / 60.0f, 1, 1.0f / 60.0f);
    ADD_FAILURE() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("differs from the model's"), std::string::npos);
  }
  fixture.world.setGravity(btVector3(0, 0, -9.81f));
  fixture.bodies.back()->setGravity(btVector3(0, 0, -9.81f));
  EXPECT_THROW(fixture.step(), ConfigError);
}

TEST(FIGNetWorld, BodiesComeAndGoMidRunAndVelocityChangesReseedHistory) {
  auto predictor = recording_predictor();
  auto* recorder = predictor.get();
  WorldFixture fixture(std::move(predictor), {}, FIGNetWorldOptions::network_alone());
  btRigidBody* first = fixture.add(std::make_unique<btSphereShape>(0.1f), 1.0, at(Vec3(0, 0, 5)));
  fixture.step(3);
  btRigidBody* second = fixture.add(std::make_unique<btSphereShape>(0.1f), 1.0, at(Vec3(3, 0, 5)));
  second->setLinearVelocity(btVector3(2, 0, 0));
  fixture.step();
  ASSERT_EQ(recorder->last_scene.objects.size(), 2u);
  // The newcomer's history was seeded from its velocity: 2 m/s over the last two steps.
  const SceneObject& seeded = recorder->last_scene.objects[1];
  EXPECT_NEAR(seeded.centers(2, 0) - seeded.centers(1, 0), 2.0 * WorldFixture::kStep, 1e-6);
  // An impulse changes the velocity before the next step.
  first->applyCentralImpulse(btVector3(0, 5, 0));
  fixture.step();
  EXPECT_NEAR(first->getLinearVelocity().y(), 5.0, 1e-4);
  fixture.world.removeRigidBody(second);
  fixture.step();
  EXPECT_EQ(recorder->last_scene.objects.size(), 1u);
  fixture.world.addRigidBody(second);  // so the fixture can remove it again
}

TEST(FIGNetWorld, RestingBodiesSleepAndWakeWhenTouched) {
  // A predictor that keeps everything still: bodies rest, fall asleep after Bullet's 2 s.
  class Still : public testing::RecordingPredictor {
   public:
    Still() : RecordingPredictor(Vec3::Zero(), 1.0 / 48.0) {}
  };
  // With the world's defaults (free flight, guard) on a floor, so that the resting bodies are in
  // contact and go through the predictor; without the rest guard, which would keep them out of
  // it (tests/bullet/test_rest_guard.cpp).
  auto predictor = std::make_unique<Still>();
  auto* recorder = predictor.get();
  FIGNetWorldOptions no_rest_guard;
  no_rest_guard.rest_guard = false;
  WorldFixture fixture(std::move(predictor), {}, no_rest_guard);
  fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  btRigidBody* resting = fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0,
                                     at(Vec3(0, 0, 0.2)));
  btRigidBody* far = fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0,
                                 at(Vec3(5, 0, 0.2)));
  fixture.step(150);  // > 2 s
  EXPECT_FALSE(resting->isActive());
  EXPECT_EQ(fixture.world.last_step_stats().sleeping_bodies, 2);
  EXPECT_EQ(fixture.world.last_step_stats().simulated_bodies, 0);
  // Moving one body next to the sleeping one wakes it; the far one sleeps on.
  far->activate(true);
  far->setWorldTransform(bullet::to_bt(at(Vec3(0.45, 0, 0.2))));
  far->getMotionState()->setWorldTransform(far->getWorldTransform());
  fixture.step();
  EXPECT_TRUE(resting->isActive());
  EXPECT_EQ(recorder->last_scene.objects.size(), 2u);
  EXPECT_EQ(fixture.world.last_step_stats().simulated_bodies, 2);
  // Without sleeping, nothing sleeps.
  FIGNetWorldOptions awake;
  awake.sleeping = false;
  WorldFixture restless(std::make_unique<Still>(), {}, awake);
  restless.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  btRigidBody* box = restless.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0,
                                  at(Vec3(0, 0, 0.2)));
  restless.step(150);
  EXPECT_TRUE(box->isActive());
  EXPECT_EQ(restless.world.last_step_stats().sleeping_bodies, 0);
}

TEST(FIGNetWorld, CollisionFilteringKeepsFilteredPairsOutOfTheGraph) {
  auto predictor = recording_predictor();
  auto* recorder = predictor.get();
  WorldFixture fixture(std::move(predictor), {}, FIGNetWorldOptions::network_alone());
  const int group_a = 2, group_b = 4;
  auto add_box = [&](const Vec3& p, int group, int mask) {
    auto shape = std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f));
    btVector3 inertia;
    shape->calculateLocalInertia(1.0f, inertia);
    fixture.motion_states.push_back(std::make_unique<btDefaultMotionState>(bullet::to_bt(at(p))));
    btRigidBody::btRigidBodyConstructionInfo info(1.0f, fixture.motion_states.back().get(),
                                                  shape.get(), inertia);
    fixture.bodies.push_back(std::make_unique<btRigidBody>(info));
    fixture.shapes.push_back(std::move(shape));
    fixture.world.addRigidBody(fixture.bodies.back().get(), group, mask);
  };
  add_box(Vec3(0, 0, 1), group_a, group_a);      // collides with group a only
  add_box(Vec3(0.45, 0, 1), group_b, group_b);   // touching, but filtered out
  add_box(Vec3(-0.45, 0, 1), group_a, group_a);  // touching and paired
  fixture.step();
  ASSERT_EQ(recorder->last_candidates.size(), 1u);
  EXPECT_EQ(recorder->last_candidates[0].a, 0);
  EXPECT_EQ(recorder->last_candidates[0].b, 2);
}

}  // namespace
}  // namespace fignet::bullet

namespace fignet::bullet {
namespace {

Trajectory core_rollout(AccelerationPredictor& predictor, const Trajectory& truth) {
  return rollout(predictor, truth);
}

TEST(FIGNetWorld, ARealModelStepsAMoviASceneWithoutNaNAsEvalRolloutsDo) {
  GenerateOptions generate;
  generate.count = 2;
  generate.seed = 5;
  generate.scene.frames = 8;
  const std::vector<Trajectory> data = generate_dataset(generate);
  ModelConfig config = ModelConfig::preset_named("small");
  config.latent_size = 16;
  config.message_passing_steps = 2;
  Trainer trainer(config, {}, data);
  trainer.run(5, nullptr);
  const std::shared_ptr<const Model> model = trainer.model();

  SceneSpec spec = sample_movi_scene({}, 42);
  spec.frames = 24;
  SolverSettings settings;
  settings.steps_per_frame = 1;  // one model step per 48 Hz frame
  BulletSimulation simulation(spec, settings,
                              [&](btDispatcher* d, btBroadphaseInterface* b, btConstraintSolver* s,
                                  btCollisionConfiguration* c) {
                                // The network alone, as core rollouts run it: none of the
                                // world's additions (the guards, free flight, sleeping; this
                                // model, 5 steps from random, drives bodies through the floor,
                                // which the tunnelling guard would stop: test_stress.cpp holds
                                // the shipped model's world to its rollouts with the guard on).
                                FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
                                options.sweep_guard = false;
                                return std::make_unique<FIGNetDynamicsWorld>(d, b, s, c, model,
                                                                             options);
                              });
  const Trajectory rollout = simulation.record();
  ASSERT_EQ(rollout.num_frames(), 24);
  for (const TrajectoryObject& object : rollout.objects) {
    for (const Pose& pose : object.poses) {
      ASSERT_TRUE(pose.position.allFinite());
      ASSERT_TRUE(pose.orientation.coeffs().allFinite());
    }
  }
  const auto& world = static_cast<FIGNetDynamicsWorld&>(simulation.world());
  EXPECT_EQ(world.last_step_stats().simulated_bodies, static_cast<int>(spec.bodies.size()));

  // `fignet eval`'s rollouts and the world are one code path: started from the world's own first
  // frames, a core rollout reproduces the world's later frames. Bullet keeps transforms in
  // float, so they agree to float rounding compounded over the steps (up to 1e-5 m over 20),
  // not bit for bit. (Before RigidBodies handed the world the bodies' own meshes, the world saw
  // the hulls' triangulation and this was off by 3e-4 m. A trained model at a resting contact
  // turns that rounding into micrometres a step: docs/graph.md, "Ties at resting contact".)
  ModelPredictor predictor(model);
  const Trajectory replayed = core_rollout(predictor, rollout);
  const int first = model->config().graph.history + 1;
  for (size_t o = 0; o < rollout.objects.size(); ++o) {
    for (int f = first; f < rollout.num_frames(); ++f) {
      const Pose& a = rollout.objects[o].poses[f];
      const Pose& b = replayed.objects[o].poses[f];
      ASSERT_LT((a.position - b.position).norm(), 1e-4) << "object " << o << " frame " << f;
      ASSERT_LT(a.orientation.angularDistance(b.orientation), 1e-4)
          << "object " << o << " frame " << f;
    }
  }
}

}  // namespace
}  // namespace fignet::bullet

namespace fignet::bullet {
namespace {

using testing::WorldFixture;

// A model that always answers "fall": every node accelerates by 3 g, contact or not.
class AlwaysFalls : public GravityPredictor {
 public:
  AlwaysFalls() : GravityPredictor(Vec3(0, 0, -30), WorldFixture::kStep) {}
};

// A model that speeds every body up: each step moves its nodes twice as far as the last did (and
// falls as gravity does), so a body's kinetic energy grows fourfold a step.
class Accelerates : public GravityPredictor {
 public:
  Accelerates() : GravityPredictor(Vec3(0, 0, -10), WorldFixture::kStep) {}
  void predict(const Scene& scene, Points& accelerations) override {
    GravityPredictor::predict(scene, accelerations);
    Eigen::Index row = 0;
    for (const SceneObject& object : scene.objects) {
      const int h = object.num_steps() - 1;
      const Points step = object.positions_at(h) - object.positions_at(h - 1);
      accelerations.middleRows(row, step.rows()) += step;
      row += step.rows();
    }
  }
};

// Passive contact only takes energy away: a model that doubles every body's speed each step has
// its island held to a tenth of its kinetic energy a step (and a millimetre's lift), and counted;
// the network alone (the guard off) lets it run away. A box pushed by a kinematic body is the
// pusher's to speed up: its island is left alone.
TEST(FIGNetWorld, TheEnergyGuardHoldsAModelThatGainsEnergy) {
  for (const bool guard : {true, false}) {
    SCOPED_TRACE(guard ? "with the guard" : "without");
    FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
    options.energy_guard = guard;
    WorldFixture fixture(std::make_unique<Accelerates>(), {}, options);
    btRigidBody* box = fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0,
                                   at(Vec3(0, 0, 50)));
    box->setLinearVelocity(btVector3(1, 0, 0));
    int held = 0;
    for (int step = 0; step < 10; ++step) {
      fixture.step();
      held += fixture.world.last_step_stats().energy_bodies;
    }
    const double speed = box->getLinearVelocity().length();
    if (guard) {
      // Falling alone brings it to 2.3 m/s in these 10 steps; a tenth more energy a step (1.1¹⁰ =
      // 2.6) keeps it under 4 m/s, where doubling gives 2¹⁰ m/s.
      EXPECT_LT(speed, 4.0);
      EXPECT_EQ(held, 10);
    } else {
      EXPECT_GT(speed, 100.0);
      EXPECT_EQ(held, 0);
    }
  }
  // A kinematic pusher touching the box: its island is driven, not guarded.
  FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
  options.energy_guard = true;
  WorldFixture fixture(std::make_unique<Accelerates>(), {}, options);
  btRigidBody* pusher = fixture.add(std::make_unique<btBoxShape>(btVector3(0.1f, 0.1f, 0.1f)), 0.0,
                                    at(Vec3(0, 0, 50)));
  pusher->setCollisionFlags(pusher->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  pusher->setActivationState(DISABLE_DEACTIVATION);
  btRigidBody* box = fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0,
                                 at(Vec3(0.31, 0, 50)));
  box->setLinearVelocity(btVector3(1, 0, 0));
  fixture.step();
  EXPECT_EQ(fixture.world.last_step_stats().energy_bodies, 0);
}

// The lowest point of a box body: its corners.
double lowest_corner(const btRigidBody& body, const btVector3& half) {
  double lowest = INFINITY;
  for (int corner = 0; corner < 8; ++corner) {
    const btVector3 local((corner & 1 ? 1 : -1) * half.x(), (corner & 2 ? 1 : -1) * half.y(),
                          (corner & 4 ? 1 : -1) * half.z());
    lowest = std::min(lowest, double((body.getWorldTransform() * local).z()));
  }
  return lowest;
}

// Whatever the model says, no body sinks into static geometry deeper than the tolerance: on a
// static plane, a static triangle mesh and a static box; without the guard, it sinks.
TEST(FIGNetWorld, ThePenetrationGuardHoldsAFallingModelOnStaticGeometry) {
  btTriangleMesh terrain;
  terrain.addTriangle(btVector3(-5, -5, 0), btVector3(5, -5, 0), btVector3(5, 5, 0));
  terrain.addTriangle(btVector3(-5, -5, 0), btVector3(5, 5, 0), btVector3(-5, 5, 0));
  for (const std::string surface : {"plane", "triangle mesh", "box"}) {
    for (const bool guard : {true, false}) {
      SCOPED_TRACE(surface + (guard ? " with the guard" : " without"));
      FIGNetWorldOptions options;
      options.penetration_guard = guard;
      options.rest_guard = false;  // it would hold the sunken box where it stops
      options.allow_gravity_mismatch = true;
      WorldFixture fixture(std::make_unique<AlwaysFalls>(), {}, options);
      if (surface == "plane") {
        fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
      } else if (surface == "triangle mesh") {
        fixture.add(std::make_unique<btBvhTriangleMeshShape>(&terrain, true), 0.0, Pose{});
      } else {
        fixture.add(std::make_unique<btBoxShape>(btVector3(5, 5, 1)), 0.0, at(Vec3(0, 0, -1)));
      }
      const btVector3 half(0.2f, 0.3f, 0.25f);
      btRigidBody* box =
          fixture.add(std::make_unique<btBoxShape>(half), 1.0,
                      at(Vec3(0.5, -0.3, 1.0),
                         Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3(1, 1, 0).normalized()))));
      box->setActivationState(DISABLE_DEACTIVATION);
      // Bullet rounds a box's corners by its margin against meshes and boxes (GJK); depths are
      // measured on that shape, so a corner may sit up to the margin deeper.
      const double margin = 0.004;
      box->getCollisionShape()->setMargin(btScalar(margin));
      double lowest = INFINITY;
      int recovered = 0;
      for (int step = 0; step < 200; ++step) {
        fixture.step();
        lowest = std::min(lowest, lowest_corner(*box, half));
        recovered += fixture.world.last_step_stats().recovered_bodies;
      }
      if (guard) {
        EXPECT_GT(lowest, -options.penetration_tolerance - margin);
        EXPECT_GT(recovered, 100);  // it is pushed out almost every step
        // Its inward velocity goes each time: it never gains downward speed.
        EXPECT_GT(box->getLinearVelocity().z(), -30 * WorldFixture::kStep - 1e-3);
      } else {
        EXPECT_LT(lowest, -1.0);
        EXPECT_EQ(recovered, 0);
      }
    }
  }
}

// A model that sinks a resting body slowly (a small downward acceleration, as a model's bias at
// rest) has it held where it reaches the tolerance, not popped up by the whole tolerance each
// time it crosses it: once it is there it stops, and no frame moves it up by more than the
// model moved it down.
TEST(FIGNetWorld, ThePenetrationGuardHoldsASlowlySinkingBodyWithoutJumps) {
  FIGNetWorldOptions options;
  options.rest_guard = false;
  options.allow_gravity_mismatch = true;
  WorldFixture fixture(std::make_unique<GravityPredictor>(Vec3(0, 0, -0.2), WorldFixture::kStep),
                       {}, options);
  fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  const btVector3 half(0.2f, 0.3f, 0.25f);
  btRigidBody* box =
      fixture.add(std::make_unique<btBoxShape>(half), 1.0, at(Vec3(0.5, -0.3, double(half.z()))));
  box->setActivationState(DISABLE_DEACTIVATION);
  double largest_rise = 0.0, lowest = INFINITY;
  int recovered = 0;
  double previous = box->getWorldTransform().getOrigin().z();
  for (int step = 0; step < 300; ++step) {
    fixture.step();
    const double height = box->getWorldTransform().getOrigin().z();
    largest_rise = std::max(largest_rise, height - previous);
    previous = height;
    lowest = std::min(lowest, lowest_corner(*box, half));
    recovered += fixture.world.last_step_stats().recovered_bodies;
  }
  EXPECT_GT(recovered, 250);  // held at the tolerance from the first ~12 frames on
  EXPECT_GT(lowest, -options.penetration_tolerance - 1e-4);
  EXPECT_LT(lowest, -options.penetration_tolerance + 1e-3);
  // Pushed out to zero depth it would rise 5 mm in a frame every time it crossed.
  EXPECT_LT(largest_rise, 1e-3);
  EXPECT_NEAR(box->getLinearVelocity().z(), 0.0, 0.2 * WorldFixture::kStep + 1e-4);
}

// A small untrained model (its answers are arbitrary but deterministic) on boxes `clearance`
// above a static plane.
struct ModelScene {
  explicit ModelScene(const FIGNetWorldOptions& options)
      : model(make_model()),
        fixture(std::make_unique<ModelPredictor>(model), model->config().graph, options) {
    fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  }
  static std::shared_ptr<const Model> make_model() {
    ModelConfig config = ModelConfig::preset_named("small");
    config.latent_size = 16;
    config.message_passing_steps = 2;
    return std::make_shared<const Model>(config);
  }
  btRigidBody* add_box(const Vec3& centre) {
    return fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0, at(centre));
  }
  std::shared_ptr<const Model> model;
  WorldFixture fixture;
};

// The world counts the simulated bodies, and the floor, whose materials lie outside the model's
// training data's; a model that does not record them counts nothing.
TEST(FIGNetWorld, CountsBodiesOfMaterialsTheModelsDataDidNotHold) {
  // Counts of the first step, and whether the floor is unfamiliar once its restitution is 0.9.
  const auto run = [](const ModelConfig& config) {
    WorldFixture fixture(std::make_shared<const Model>(config),
                         FIGNetWorldOptions::network_alone());
    btRigidBody* floor =
        fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
    floor->setFriction(0.3f);
    floor->setRestitution(0.5f);
    // Metal and rubber as MOVi-A has them, then a body of friction 1.2: 5 cm above the floor,
    // within the collision radius, 1 m apart.
    const double materials[][2] = {{0.4, 0.3}, {0.8, 0.7}, {1.2, 0.3}};
    for (int i = 0; i < 3; ++i) {
      btRigidBody* box = fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0,
                                     at(Vec3(1.0 * i, 0, 0.25)));
      box->setFriction(static_cast<btScalar>(materials[i][0]));
      box->setRestitution(static_cast<btScalar>(materials[i][1]));
    }
    fixture.step();
    const FIGNetStepStats first = fixture.world.last_step_stats();
    floor->setRestitution(0.9f);
    fixture.step();
    return std::pair(first, fixture.world.last_step_stats().unfamiliar_floor);
  };
  ModelConfig config = ModelScene::make_model()->config();
  config.friction = {0.4, 0.8};
  config.restitution = {0.3, 0.7};
  config.floor_friction = {0.3, 0.3};
  config.floor_restitution = {0.5, 0.5};
  const auto [recorded, floor_changed] = run(config);
  EXPECT_EQ(recorded.simulated_bodies, 3);
  EXPECT_EQ(recorded.unfamiliar_bodies, 1);
  EXPECT_FALSE(recorded.unfamiliar_floor);
  EXPECT_TRUE(floor_changed);
  config.friction = config.restitution = config.floor_friction = config.floor_restitution = {};
  const auto [unknown, unknown_floor_changed] = run(config);
  EXPECT_EQ(unknown.simulated_bodies, 3);
  EXPECT_EQ(unknown.unfamiliar_bodies, 0);
  EXPECT_FALSE(unknown_floor_changed);
}

// The free-flight path changes nothing for bodies in contact: their graph and the network's
// answer for them do not depend on bodies they have no edge to. With every body in contact the
// two runs are the same bits, and a body far up, left out of the network, leaves the others'
// graph and bits as if it were not there while it falls exactly. (With free flight off that body's
// rows join the network's products, which may change the others' rounding, and this untrained
// network amplifies rounding at once: that run is not compared.)
TEST(FIGNetWorld, FreeFlightLeavesBodiesInContactAsTheNetworkMovesThem) {
  auto run = [](bool with_flyer, bool free_flight) {
    SCOPED_TRACE(fmt::format("flyer {}, free flight {}", with_flyer, free_flight));
    FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
    options.free_flight = free_flight;
    ModelScene scene(options);
    std::vector<btRigidBody*> resting;
    for (int i = 0; i < 3; ++i) resting.push_back(scene.add_box(Vec3(1.0 * i, 0.3 * i, 0.25)));
    resting.push_back(scene.add_box(Vec3(0.0, 0.0, 0.7)));  // on the first: a stack
    btRigidBody* flyer = with_flyer ? scene.add_box(Vec3(10, 10, 30)) : nullptr;
    std::vector<Vec3> positions;
    std::vector<Eigen::Vector4d> orientations;  // quaternion coefficients
    for (int step = 0; step < 6; ++step) {
      scene.fixture.step();
      for (btRigidBody* body : resting) {
        const Pose pose = scene.fixture.world.precise_pose(*body);
        positions.push_back(pose.position);
        orientations.push_back(pose.orientation.coeffs());
      }
      const FIGNetStepStats& stats = scene.fixture.world.last_step_stats();
      EXPECT_EQ(stats.simulated_bodies, free_flight ? 4 : 4 + with_flyer);
      EXPECT_EQ(stats.free_flight_bodies, free_flight ? with_flyer : 0);
    }
    if (flyer && free_flight) {
      // Released at rest in free flight: seeded at the top of its parabola (seed_falling).
      const double n = 6, dt = WorldFixture::kStep;
      EXPECT_NEAR(scene.fixture.world.precise_pose(*flyer).position.z(),
                  30 - 0.5 * n * n * dt * dt * 10, 1e-9);
    }
    return std::pair(positions, orientations);
  };
  const auto network_only = run(false, false);
  EXPECT_EQ(run(false, true), network_only);
  EXPECT_EQ(run(true, true), network_only);
  // The flyer with free flight off still goes through the network, with everything else.
  run(true, false);
}

}  // namespace
}  // namespace fignet::bullet

namespace fignet::bullet {
namespace {

// The model's floor mesh spans ±40 m; a body resting 1 km from the origin still meets it, centred
// under it, and goes through the network; near the origin the floor stays where training had it.
TEST(FIGNetWorld, ABodyFarFromTheOriginStillMeetsTheFloor) {
  for (const double x : {1000.0, 3.0}) {
    auto predictor = testing::recording_predictor();
    auto* recorder = predictor.get();
    testing::WorldFixture fixture(std::move(predictor));
    fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
    Pose pose;
    pose.position = Vec3(x, 0, 0.25);
    fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0, pose);
    // A body high up and far away pairs with the plane too (its box spans everything), but
    // neither enters the graph nor moves the floor.
    pose.position = Vec3(-x, 500, 50);
    fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0, pose);
    fixture.step();
    EXPECT_EQ(fixture.world.last_step_stats().simulated_bodies, 1) << x;
    EXPECT_EQ(fixture.world.last_step_stats().free_flight_bodies, 1) << x;
    ASSERT_TRUE(recorder->last_scene.floor.has_value());
    EXPECT_NEAR(recorder->last_scene.floor->center_x, x > 100 ? x : 0.0, 1e-3);
    ASSERT_EQ(recorder->last_candidates.size(), 1u);
    EXPECT_EQ(recorder->last_candidates[0].b, 1);  // the floor, after the body
  }
}

// The world searches contacts to choose the bodies it passes; when it passes all it searched, the
// network's graph is built from that search (one search a step), and when it leaves some to free
// flight, the scene it passes is numbered anew and searched again.
TEST(FIGNetWorld, TheNetworkReusesTheWorldsContactSearchWhenTheSceneStands) {
  auto predictor = testing::recording_predictor();
  auto* recorder = predictor.get();
  testing::WorldFixture fixture(std::move(predictor));
  fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  Pose pose;
  pose.position = Vec3(0, 0, 0.25);
  fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0, pose);
  fixture.step();
  EXPECT_EQ(recorder->calls, 1);
  EXPECT_EQ(recorder->searched_calls, 1);
  // The box and the floor mesh after it, with the face pairs between them.
  EXPECT_EQ(recorder->last_interacting, (std::vector<char>{1, 1}));
  EXPECT_FALSE(recorder->last_contacts.faces.empty());
  for (const FacePair& pair : recorder->last_contacts.faces) {
    EXPECT_EQ(pair.object_a, 0);
    EXPECT_EQ(pair.object_b, 1);
  }
  // A sphere in the air off the box's top corner: their boxes overlap (a broadphase pair), their
  // surfaces are 0.13 m apart, out of the collision radius.
  pose.position = Vec3(0.39, 0.39, 0.64);
  fixture.add(std::make_unique<btSphereShape>(0.2f), 1.0, pose);
  fixture.step();
  EXPECT_EQ(fixture.world.last_step_stats().free_flight_bodies, 1);
  EXPECT_EQ(recorder->calls, 2);
  EXPECT_EQ(recorder->searched_calls, 1);
  EXPECT_EQ(recorder->last_scene.objects.size(), 1u);
}

// Bodies on the floor farther apart than its mesh reaches (±40 m) each have floor under them: the
// first group the scene's floor, the others a floor patch of the same mesh and properties.
TEST(FIGNetWorld, BodiesFarApartEachHaveFloorUnderThem) {
  auto predictor = testing::recording_predictor();
  auto* recorder = predictor.get();
  testing::WorldFixture fixture(std::move(predictor));
  fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  const std::vector<Vec3> places = {Vec3(2, 0, 0.25), Vec3(-3, 1, 0.25), Vec3(500, 80, 0.25),
                                    Vec3(503, 80, 0.25)};
  for (const Vec3& place : places) {
    fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0, at(place));
  }
  fixture.step();
  EXPECT_EQ(fixture.world.last_step_stats().simulated_bodies, 4);
  const Scene& scene = recorder->last_scene;
  ASSERT_EQ(scene.objects.size(), 5u);  // four bodies, one patch; the scene's floor is last
  ASSERT_TRUE(scene.floor.has_value());
  EXPECT_EQ(scene.floor->center_x, 0.0);  // as in training: the group near the origin
  const SceneObject& patch = scene.objects[4];
  EXPECT_TRUE(patch.kinematic);
  const Vec3 patch_center = patch.centers.row(patch.num_steps() - 1).transpose();
  EXPECT_NEAR((patch_center - Vec3(501.5, 80, 0)).norm(), 0.0, 1e-6);
  const TriangleMesh floor = make_floor_mesh(40.0, 1);
  EXPECT_EQ(patch.mesh->num_vertices(), floor.num_vertices());
  EXPECT_EQ(patch.properties.friction, scene.floor->properties.friction);
  // Each body pairs with the floor under it.
  std::set<std::pair<int, int>> pairs;
  for (const ObjectPair& pair : recorder->last_candidates) pairs.emplace(pair.a, pair.b);
  const int scene_floor = 5;
  for (const auto& [body, floor_index] :
       std::vector<std::pair<int, int>>{{0, scene_floor}, {1, scene_floor}, {2, 4}, {3, 4}}) {
    EXPECT_TRUE(pairs.count({body, floor_index})) << "body " << body;
  }
}

}  // namespace
}  // namespace fignet::bullet

namespace fignet::bullet {
namespace {

// A sphere shape standing for a 20,000-vertex mesh, resting on a plane in a world.
btRigidBody* add_fine_sphere(testing::WorldFixture& fixture) {
  fixture.add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{});
  btRigidBody* ball = fixture.add(std::make_unique<btSphereShape>(0.5f), 1.0, at(Vec3(0, 0, 0.52)));
  fixture.world.set_shape_mesh(*ball->getCollisionShape(),
                               std::make_shared<const TriangleMesh>(make_sphere(0.5, 140, 143)));
  return ball;
}

// The node budget: a fine mesh enters the graph simplified, within its tolerance of the shape.
TEST(FIGNetWorld, AFineMeshEntersTheGraphWithinTheNodeBudget) {
  for (const int budget : {0, 64}) {
    FIGNetWorldOptions options;
    options.max_graph_vertices = budget;
    options.free_flight = false;
    auto predictor = recording_predictor();
    auto* recorder = predictor.get();
    WorldFixture fixture(std::move(predictor), {}, options);
    add_fine_sphere(fixture);
    fixture.step();
    ASSERT_EQ(recorder->calls, 1);
    const TriangleMesh& seen = *recorder->last_scene.objects[0].mesh;
    if (budget == 0) {
      EXPECT_EQ(seen.num_vertices(), make_sphere(0.5, 140, 143).num_vertices());
    } else {
      // 2 % of the 1 m sphere stops the simplifier near 100 vertices, above the budget of 64.
      EXPECT_LT(seen.num_vertices(), 150);
      EXPECT_TRUE(seen.is_closed());
      const Eigen::VectorXd radii = seen.vertices().rowwise().norm();
      EXPECT_NEAR(radii.maxCoeff(), 0.5, 1e-9);  // its vertices are the mesh's own
    }
    EXPECT_GE(fixture.world.last_step_stats().mesh_nodes, seen.num_vertices());
  }
}

// A model's own resolution is the default budget; a model file that predates it leaves 1000.
TEST(FIGNetWorld, TheModelsTrainingResolutionIsTheDefaultBudget) {
  for (const int resolution : {0, 64}) {
    ModelConfig config = ModelConfig::preset_named("small");
    config.latent_size = 8;
    config.message_passing_steps = 1;
    config.mesh_vertices = resolution;
    auto model = std::make_shared<const Model>(config);
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    FIGNetWorldOptions options;
    options.free_flight = false;
    FIGNetDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration, model, options);
    btSphereShape shape(0.5f);
    btDefaultMotionState state(to_bt(at(Vec3(0, 0, 3))));
    btRigidBody ball(btRigidBody::btRigidBodyConstructionInfo(1.0f, &state, &shape,
                                                              btVector3(0.1f, 0.1f, 0.1f)));
    world.addRigidBody(&ball);
    world.set_shape_mesh(shape, std::make_shared<const TriangleMesh>(make_sphere(0.5, 140, 143)));
    world.stepSimulation(btScalar(config.time_step), 1, btScalar(config.time_step));
    const int nodes = world.last_step_stats().mesh_nodes;
    if (resolution == 0) {
      EXPECT_GT(nodes, 500);
      EXPECT_LE(nodes, FIGNetWorldOptions::kDefaultGraphVertices);
    } else {
      EXPECT_LT(nodes, 150);
    }
    world.removeRigidBody(&ball);
  }
}

}  // namespace
}  // namespace fignet::bullet
