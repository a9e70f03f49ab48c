// The world's rest guard (FIGNetWorldOptions::rest_guard): Coulomb's static friction under gravity
// for bodies that stand at rest, whatever the model says.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "fignet/error.h"
#include "world_fixture.h"

namespace fignet::bullet {
namespace {

using testing::at;
using testing::WorldFixture;

constexpr double kStep = WorldFixture::kStep;

// A model that lets a resting body creep: every node accelerates sideways by 0.2 m/s² and
// nothing falls, as the trained models' small bias at rest does (0.3 mm in the first step).
class Creeps : public GravityPredictor {
 public:
  Creeps() : GravityPredictor(Vec3(0.2, 0, 0), kStep) {}
};

// A model that keeps every velocity as it is.
class Still : public GravityPredictor {
 public:
  Still() : GravityPredictor(Vec3::Zero(), kStep) {}
};

FIGNetWorldOptions with_rest_guard(bool on) {
  FIGNetWorldOptions options;
  options.rest_guard = on;
  options.allow_gravity_mismatch = true;
  return options;
}

struct Floor : WorldFixture {
  explicit Floor(std::unique_ptr<AccelerationPredictor> predictor, bool guard = true,
                 double friction = 0.5)
      : WorldFixture(std::move(predictor), {}, with_rest_guard(guard)) {
    add(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0), 0.0, Pose{})
        ->setFriction(btScalar(friction));
  }
  btRigidBody* box(const Vec3& centre, double half = 0.2,
                   const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity()) {
    const auto h = btScalar(half);
    return add(std::make_unique<btBoxShape>(btVector3(h, h, h)), 1.0, at(centre, orientation));
  }
};

double distance_from(const btRigidBody& body, const Vec3& start) {
  return (from_bt(body.getWorldTransform().getOrigin()) - start).norm();
}

// A creeping model slides a resting cube 0.5·0.2·t² (10.8 m over 500 steps); the guard keeps it
// where it stands, and Bullet's rules then put it to sleep.
TEST(RestGuard, ACubeAtRestStaysWhereItStandsAndSleeps) {
  for (const bool guard : {true, false}) {
    SCOPED_TRACE(guard ? "with the rest guard" : "without");
    Floor floor(std::make_unique<Creeps>(), guard);
    const Vec3 start(0.3, -0.2, 0.2);
    btRigidBody* cube = floor.box(start);
    cube->setActivationState(DISABLE_DEACTIVATION);
    int rested = 0;
    for (int step = 0; step < 500; ++step) {
      floor.step();
      rested += floor.world.last_step_stats().rested_bodies;
    }
    if (guard) {
      EXPECT_LT(distance_from(*cube, start), 1e-6);  // Bullet's float transform
      EXPECT_EQ(rested, 500);
      EXPECT_EQ(cube->getLinearVelocity().length(), 0.0f);
    } else {
      EXPECT_NEAR(distance_from(*cube, start), 0.5 * 0.2 * std::pow(500 * kStep, 2), 0.1);
      EXPECT_EQ(rested, 0);
    }
  }
  Floor sleepy(std::make_unique<Creeps>());
  btRigidBody* cube = sleepy.box(Vec3(0, 0, 0.2));
  sleepy.step(150);  // > Bullet's 2 s of deactivation time
  EXPECT_FALSE(cube->isActive());
}

// Stacks stand: each cube rests on the one below once that one is held. A cube that overhangs
// the one it stands on is left to the model, and so is that one, which it touches while it moves.
TEST(RestGuard, StacksStandAndAnOverhangingCubeIsLeftToTheModel) {
  Floor floor(std::make_unique<Creeps>());
  std::vector<btRigidBody*> stack;
  std::vector<Vec3> starts;
  for (int level = 0; level < 3; ++level) {
    starts.emplace_back(0.05 * level, 0, 0.2 + 0.4 * level);
    stack.push_back(floor.box(starts.back()));
  }
  const Vec3 base_start(1.0, 0, 0.2), overhang_start(1.0 + 0.25, 0, 0.6);  // 5 cm past the edge
  btRigidBody* base = floor.box(base_start);
  btRigidBody* overhanging = floor.box(overhang_start);
  floor.step();
  EXPECT_EQ(floor.world.last_step_stats().rested_bodies, 3);
  floor.step(47);
  for (int level = 0; level < 3; ++level) {
    EXPECT_LT(distance_from(*stack[level], starts[level]), 1e-6) << "level " << level;
  }
  EXPECT_GT(distance_from(*base, base_start), 0.05);
  EXPECT_GT(distance_from(*overhanging, overhang_start), 0.05);
}

// The friction cone: on a 30° slope a cube stands where the combined friction (the product of
// the two bodies' frictions, as Bullet combines them) exceeds tan 30° = 0.58, and is left to the
// model where it does not.
TEST(RestGuard, ACubeOnASlopeStandsOnlyWithinTheFrictionCone) {
  const Eigen::Quaterniond slope(Eigen::AngleAxisd(M_PI / 6, Vec3::UnitY()));
  for (const double friction : {1.0, 0.5}) {
    SCOPED_TRACE(::testing::Message() << "friction " << friction << " each");
    WorldFixture fixture(std::make_unique<Still>(), {}, with_rest_guard(true));
    fixture.add(std::make_unique<btBoxShape>(btVector3(3, 3, 0.5)), 0.0, at(Vec3::Zero(), slope))
        ->setFriction(btScalar(friction));
    btRigidBody* cube = fixture.add(std::make_unique<btBoxShape>(btVector3(0.2f, 0.2f, 0.2f)), 1.0,
                                    at(slope * Vec3(0, 0, 0.7), slope));
    cube->setFriction(btScalar(friction));
    fixture.step();
    EXPECT_EQ(fixture.world.last_step_stats().rested_bodies, friction * friction > 0.58 ? 1 : 0);
  }
}

// What is not at rest is left to the model: a cube balanced on an edge (its centre of mass
// beside it), a cube pushed by a force, a cube touched by a moving one, a cube sliding faster
// than friction stops in a step (μ·|g|·dt = 0.25·10/48 = 0.052 m/s).
TEST(RestGuard, WhatIsNotAtRestIsLeftToTheModel) {
  auto rested_after_one_step = [](const std::function<void(Floor&)>& setup) {
    Floor floor(std::make_unique<Still>());
    setup(floor);
    floor.step();
    return floor.world.last_step_stats().rested_bodies;
  };
  EXPECT_EQ(rested_after_one_step([](Floor& floor) { floor.box(Vec3(0, 0, 0.2)); }), 1);
  EXPECT_EQ(rested_after_one_step([](Floor& floor) {
              const double turn = M_PI / 6;  // on an edge, its centre 0.07 m beside it
              floor.box(Vec3(0, 0, 0.2 * (std::cos(turn) + std::sin(turn))), 0.2,
                        Eigen::Quaterniond(Eigen::AngleAxisd(turn, Vec3::UnitY())));
            }),
            0);
  EXPECT_EQ(rested_after_one_step([](Floor& floor) {
              floor.box(Vec3(0, 0, 0.2))->applyCentralForce(btVector3(0.5f, 0, 0));
            }),
            0);
  EXPECT_EQ(rested_after_one_step([](Floor& floor) {
              floor.box(Vec3(0, 0, 0.2));
              floor.box(Vec3(0.4, 0, 0.2))->setLinearVelocity(btVector3(-1, 0, 0));
            }),
            0);
  for (const double speed : {0.04, 0.06}) {
    EXPECT_EQ(rested_after_one_step([&](Floor& floor) {
                floor.box(Vec3(0, 0, 0.2))->setLinearVelocity(btVector3(btScalar(speed), 0, 0));
              }),
              speed < 0.25 * 10 * kStep ? 1 : 0)
        << speed << " m/s";
  }
}

// Held bodies leave the network: a scene at rest costs no prediction, and a body falling onto a
// held one sees it in its graph as an obstacle that does not move.
TEST(RestGuard, HeldBodiesLeaveTheNetworkAndStayStillObstacles) {
  auto predictor = testing::recording_predictor();
  const testing::RecordingPredictor* recorder = predictor.get();
  Floor floor(std::move(predictor));
  floor.box(Vec3(0, 0, 0.2));
  floor.step(10);
  EXPECT_EQ(recorder->calls, 0);
  EXPECT_EQ(floor.world.last_step_stats().rested_bodies, 1);
  EXPECT_EQ(floor.world.last_step_stats().free_flight_bodies, 0);
  btRigidBody* falling = floor.box(Vec3(0.1, 0, 0.65));  // 5 cm above it
  falling->setLinearVelocity(btVector3(0, 0, -1));
  floor.step();
  EXPECT_EQ(recorder->calls, 1);
  const FIGNetStepStats& stats = floor.world.last_step_stats();
  EXPECT_EQ(stats.rested_bodies, 1);
  EXPECT_EQ(stats.simulated_bodies, 1);
  ASSERT_EQ(recorder->last_scene.objects.size(), 2u);
  const SceneObject& held = recorder->last_scene.objects[1];
  EXPECT_TRUE(held.kinematic);
  EXPECT_EQ(held.next_positions, held.positions_at(held.num_steps() - 1));
  EXPECT_EQ(held.positions_at(0), held.positions_at(held.num_steps() - 1));
}

// Options are checked, and the network alone has no rest guard.
TEST(RestGuard, ANegativeContactDistanceIsRejected) {
  FIGNetWorldOptions options;
  options.rest_contact_distance = -1;
  EXPECT_THROW(WorldFixture(std::make_unique<Still>(), {}, options), ConfigError);
  EXPECT_FALSE(FIGNetWorldOptions::network_alone().rest_guard);
}

}  // namespace
}  // namespace fignet::bullet
