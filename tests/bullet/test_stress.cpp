// What must never fail at the extremes, with the shipped model in a FIGNet world: no NaN or inf
// anywhere, and no body through the floor at 10, 20 and 50 m/s.
#include <gtest/gtest.h>

#include <algorithm>
#include <string_view>
#include <utility>

#include "../error_text.h"
#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/bullet/movi.h"
#include "fignet/bullet/stress.h"
#include "fignet/graph/scene.h"
#include "fignet/io/model_file.h"
#include "fignet/rollout/predictor.h"

namespace fignet::bullet {
namespace {

std::vector<Simulator> shipped_model_world() {
  auto model = std::make_shared<const Model>(
      load_model(std::string(FIGNET_SOURCE_DIR) + "/models/movi-a-small.h5"));
  return stress_simulators({{"movi-a-small", model}});
}

TEST(Stress, SimulatorsSayHowTheyAverage) {
  auto model = std::make_shared<const Model>(
      load_model(std::string(FIGNET_SOURCE_DIR) + "/models/movi-a-small.h5"));
  std::vector<std::string> names;
  for (const Simulator& sim : stress_simulators({{"m", model}}, 2, 1, true))
    names.push_back(sim.name);
  EXPECT_EQ(names, (std::vector<std::string>{"Bullet 240 Hz",
                                             "FIGNet m (network alone, 2 turns, mirrored)",
                                             "FIGNet m (2 turns, mirrored)"}));
  // And the mirror reaches the world: the first frame of the MOVi cube at rest moves the cube
  // otherwise than without it (the network alone; 2 turns each).
  const std::vector<StressCase> cases = select_stress_cases({"MOVi cube at rest"}, 0.01);
  ASSERT_EQ(cases.size(), 1u);
  const auto plain = run_stress_case(cases[0], stress_simulators({{"m", model}}, 2, 1, false));
  const auto mirrored = run_stress_case(cases[0], stress_simulators({{"m", model}}, 2, 1, true));
  const Vec3 a = plain[1].trajectory.objects[0].poses.back().position;
  const Vec3 b = mirrored[1].trajectory.objects[0].poses.back().position;
  EXPECT_GT((a - b).norm(), 1e-9);
}

// Every case, shortened to a few frames; the 100-object pile, which costs seconds per frame, is
// left out and not built (the 20,000-vertex sphere is in: the node budget makes it cheap).
TEST(Stress, EveryCaseStaysFinite) {
  const auto sims = shipped_model_world();
  const auto all_but_the_100_pile = [](std::string_view name, std::string_view) {
    return name != "100-object pile";
  };
  for (const StressCase& c : stress_cases(0.01, all_but_the_100_pile)) {
    const std::vector<StressRun> runs = run_stress_case(c, sims);
    for (const StressRun& run : runs) {
      EXPECT_TRUE(run.finite) << c.name << " in " << run.simulator;
    }
    // The world as users get it (the last simulator; its penetration guard) keeps every body
    // within 1 cm of the floor, whatever the model.
    EXPECT_GT(runs.back().lowest, -0.01) << c.name << " in " << runs.back().simulator;
  }
}

// The floor impacts at full length: with the network alone the cube (1 m) never gets its lowest
// point a quarter of its size below the floor (the sweep guard), with the world's penetration
// guard not 1 cm; native Bullet itself sinks 0.3 m into it at 50 m/s, and is only held to not
// passing through (its centre stays above the floor).
TEST(Stress, NoTunnellingThroughTheFloorAtSpeed) {
  const auto sims = shipped_model_world();
  const auto floor_impacts = [](std::string_view name, std::string_view group) {
    return group == "speed" && name.find("floor") != std::string_view::npos;
  };
  const std::vector<StressCase> cases = stress_cases(1.0, floor_impacts);
  ASSERT_EQ(cases.size(), 3u);
  for (const StressCase& c : cases) {
    const std::vector<StressRun> runs = run_stress_case(c, sims);
    for (size_t i = 0; i < runs.size(); ++i) {
      ASSERT_TRUE(runs[i].finite) << c.name << " in " << runs[i].simulator;
      // Bullet itself, the network alone (with the sweep guard), the world with its guards.
      const double floor = i == 0 ? -0.5 : i + 1 < runs.size() ? -0.25 : -0.01;
      EXPECT_GT(runs[i].lowest, floor) << c.name << " in " << runs[i].simulator;
    }
  }
}

// The settled pile of 4-8 t bodies, 70-5000x MOVi-A's masses, for 500 steps in the world as
// users get it: shown the network at the data's masses (PredictionOptions::fit_masses) it stays
// within 7.5 cm and comes to rest; shown as they are, it scattered 17 m at 3 m/s.
TEST(Stress, TheWorldHoldsAPileOfBodiesFarHeavierThanTheData) {
  const std::vector<Simulator> sims = shipped_model_world();
  const std::vector<StressCase> cases = select_stress_cases({"10-object pile at rest"}, 0.25);
  ASSERT_EQ(cases.size(), 1u);
  const std::vector<StressRun> runs = run_stress_case(cases[0], {sims.front(), sims.back()});
  ASSERT_TRUE(runs.back().finite);
  EXPECT_LT(runs.back().drift, 0.3);
  EXPECT_LT(runs.back().late_speed, 0.05);
}

// The in-distribution rest case starts where Bullet itself holds a resting MOVi cube (its
// collision margin above the floor): native Bullet keeps its height within 0.1 mm; sideways it
// creeps by itself, ~7 µm per frame with Kubric's solver settings (no warm starting), which
// bounds what "at rest" can mean in this data.
TEST(Stress, TheMoviCubeStartsWhereBulletRestsIt) {
  const std::vector<StressCase> cases = select_stress_cases({"MOVi cube at rest"}, 0.1);
  ASSERT_EQ(cases.size(), 1u);
  const std::vector<StressRun> runs =
      run_stress_case(cases[0], {Simulator{"Bullet 240 Hz", {}, {}}});
  ASSERT_EQ(runs.size(), 1u);
  const Pose& start = cases[0].scene.bodies[0].pose;
  const Pose& end = runs[0].trajectory.objects[0].poses.back();
  EXPECT_NEAR(end.position.z(), start.position.z(), 1e-4);
  EXPECT_LT(runs[0].drift, 5e-3);
  EXPECT_LT(runs[0].drift_degrees, 0.05);
}

// The first-step fall against physics: a world whose predictor answers free fall drops every
// resting body by exactly |g|·dt² in the first frame (1), and native Bullet holds the MOVi cube on
// the floor and the 2-stack, whose upper cube it lifts a little (the stack starts 5 mm apart,
// Bullet rests two bodies 10 mm apart), so its largest drop is the bottom cube's ~0.
TEST(Stress, FirstStepFallIsTheFirstFramesDropOverFreeFall) {
  const std::vector<StressCase> cases =
      select_stress_cases({"MOVi cube at rest", "stack of 2 MOVi cubes"}, 0.01);
  ASSERT_EQ(cases.size(), 2u);
  const double step = 1.0 / 48.0;
  SolverSettings one_step;
  one_step.steps_per_frame = 1;
  const Simulator falls{"free fall", one_step,
                        [&](btDispatcher* d, btBroadphaseInterface* b, btConstraintSolver* s,
                            btCollisionConfiguration* c) {
                          FIGNetWorldOptions options = FIGNetWorldOptions::network_alone();
                          options.allow_gravity_mismatch = true;
                          return std::make_unique<FIGNetDynamicsWorld>(
                              d, b, s, c, std::make_unique<GravityPredictor>(Vec3(0, 0, -10), step),
                              GraphConfig{}, step, Vec3(0, 0, -10), options);
                        }};
  for (const StressCase& c : cases) {
    const std::vector<StressRun> runs =
        run_stress_case(c, {Simulator{"Bullet 240 Hz", {}, {}}, falls});
    ASSERT_TRUE(runs[0].finite && runs[1].finite) << c.name;
    EXPECT_LT(std::abs(runs[0].first_step_fall), 0.05) << c.name;
    EXPECT_NEAR(runs[1].first_step_fall, 1.0, 1e-3) << c.name;
    // The upper cube's own first frame in Bullet: it rises.
    if (runs[0].trajectory.objects.size() == 2) {
      const auto& top = runs[0].trajectory.objects[1].poses;
      EXPECT_GT(top[1].position.z(), top[0].position.z()) << c.name;
    }
  }
  // Not a rest case: no first-step figure.
  const std::vector<StressCase> drop = select_stress_cases({"canonical"}, 0.01);
  ASSERT_FALSE(drop.empty());
  ASSERT_FALSE(drop[0].at_rest);
  EXPECT_EQ(run_stress_case(drop[0], {Simulator{"Bullet 240 Hz", {}, {}}})[0].first_step_fall, 0.0);
}

// A MOVi sphere resting on an equatorial facet on a MOVi cube: Bullet holds both (their first
// frame drops under 5 % of free fall, and they stay within 2 cm over the case's 480 frames).
TEST(Stress, BulletHoldsTheSphereOnTheCube) {
  const std::vector<StressCase> cases = select_stress_cases({"MOVi sphere on a MOVi cube"});
  ASSERT_EQ(cases.size(), 1u);
  ASSERT_EQ(cases[0].scene.bodies.size(), 2u);
  const BodySpec& sphere = cases[0].scene.bodies[1];
  // It rests on a facet: its lowest face is horizontal.
  const Points turned =
      sphere.mesh->face_normals() * sphere.pose.orientation.toRotationMatrix().transpose();
  EXPECT_NEAR(turned.col(2).minCoeff(), -1.0, 1e-9);
  const std::vector<StressRun> runs =
      run_stress_case(cases[0], {Simulator{"Bullet 240 Hz", {}, {}}});
  ASSERT_TRUE(runs[0].finite);
  EXPECT_EQ(runs[0].trajectory.num_frames(), 480);
  EXPECT_LT(std::abs(runs[0].first_step_fall), 0.05);
  EXPECT_LT(runs[0].drift, 0.02);
}

// The pile's other arrangements are other heaps of the same kind: ten bodies each, bodies left
// resting on others after settling (their lowest point well above the floor; 11 in the four
// here, 1-4 each: held loosely, since settling is chaotic and builds differ in the last bits),
// no two arrangements alike.
TEST(Stress, PileArrangementsAreDifferentHeaps) {
  const std::vector<StressCase> piles =
      stress_cases(0.01, [](std::string_view name, std::string_view group) {
        return name == "10-object pile at rest" || group == "piles";
      });
  ASSERT_EQ(piles.size(), 4u);
  int on_others = 0;
  for (size_t i = 0; i < piles.size(); ++i) {
    const SceneSpec& scene = piles[i].scene;
    ASSERT_EQ(scene.bodies.size(), 10u) << piles[i].name;
    EXPECT_TRUE(piles[i].at_rest);
    for (const BodySpec& body : scene.bodies) {
      const double lowest = posed_vertices(*body.mesh, body.pose).col(2).minCoeff();
      if (lowest > scene.floor->height + 0.1) ++on_others;
    }
    for (size_t j = 0; j < i; ++j) {
      double apart = 0.0;
      for (size_t b = 0; b < scene.bodies.size(); ++b) {
        apart = std::max(
            apart, (scene.bodies[b].pose.position - piles[j].scene.bodies[b].pose.position).norm());
      }
      EXPECT_GT(apart, 0.1) << piles[i].name << " against " << piles[j].name;
    }
  }
  EXPECT_GE(on_others, 4);
}

std::vector<std::string> names(const std::vector<StressCase>& cases) {
  std::vector<std::string> out;
  for (const StressCase& c : cases) out.push_back(c.name);
  return out;
}

// Filters pick by a part of the name or a whole group; several pick the cases any of them names,
// once each and in the suite's order, whatever the filters' order. A case selected alone is the
// case of the whole suite: its scene is built the same way, only not unless it is kept.
TEST(Stress, SelectingCasesByNameAndGroup) {
  std::vector<std::pair<std::string, std::string>> listed;  // name and group, nothing built
  EXPECT_TRUE(stress_cases(0.01, [&](std::string_view name, std::string_view group) {
                listed.emplace_back(name, group);
                return false;
              }).empty());
  const std::vector<StressCase> all = select_stress_cases({}, 0.01);
  ASSERT_EQ(all.size(), listed.size());
  for (size_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i].name, listed[i].first);
  const std::vector<StressCase> alone = select_stress_cases({"arrangement 2"}, 0.01);
  ASSERT_EQ(alone.size(), 1u);
  const auto same = std::find_if(all.begin(), all.end(),
                                 [&](const StressCase& c) { return c.name == alone[0].name; });
  ASSERT_NE(same, all.end());
  ASSERT_EQ(alone[0].scene.bodies.size(), same->scene.bodies.size());
  for (size_t b = 0; b < same->scene.bodies.size(); ++b) {
    EXPECT_EQ(alone[0].scene.bodies[b].pose.position, same->scene.bodies[b].pose.position);
  }
  std::vector<std::string> expected;
  for (const auto& [name, group] : listed) {
    if (group == "stacks" || name == "10-object pile at rest") expected.push_back(name);
  }
  // The pile, stacks of 2-5 cubes and of 2-3 MOVi cubes, the MOVi sphere on a MOVi cube.
  ASSERT_EQ(expected.size(), 8u);
  EXPECT_EQ(names(select_stress_cases({"stacks", "pile at rest", "stack of 2"}, 0.01)), expected);
  EXPECT_EQ(names(select_stress_cases({"rest"}, 0.01)),
            (std::vector<std::string>{"one cube at rest", "MOVi cube at rest",
                                      "10-object pile at rest"}));
  EXPECT_EQ(names(select_stress_cases({"MOVi cube at rest"}, 0.01)),
            std::vector<std::string>{"MOVi cube at rest"});
}

// MOVi's bodies are thrown at several metres per second and fall from up to 5 m: many steps are
// longer than the collision radius, and their impacts are in the training data. With the shipped
// model (the network alone, as `fignet compare`'s first FIGNet row) the tunnelling guard must
// sweep those steps and leave every one to the network. Until 2026-12-06 it swept each fast
// body's whole shape and stopped it dead where it first touched anything, and `fignet compare`'s
// errors were 2.5× those of `fignet eval`'s rollouts.
TEST(Stress, TheTunnellingGuardLeavesMoviScenesToTheShippedModel) {
  auto model = std::make_shared<const Model>(
      load_model(std::string(FIGNET_SOURCE_DIR) + "/models/movi-a-small.h5"));
  int guarded = 0;
  double fastest_step = 0.0;
  for (const std::uint64_t seed : {3u, 4u}) {
    SceneSpec spec = sample_movi_scene({}, seed);
    SolverSettings settings;
    settings.steps_per_frame = 1;
    BulletSimulation simulation(spec, settings,
                                [&](btDispatcher* d, btBroadphaseInterface* b,
                                    btConstraintSolver* s, btCollisionConfiguration* c) {
                                  return std::make_unique<FIGNetDynamicsWorld>(
                                      d, b, s, c, model, FIGNetWorldOptions::network_alone());
                                });
    // Bullet's internal tick callback runs after each step, when its statistics are complete.
    simulation.world().setInternalTickCallback(
        [](btDynamicsWorld* world, btScalar) {
          *static_cast<int*>(world->getWorldUserInfo()) +=
              static_cast<FIGNetDynamicsWorld*>(world)->last_step_stats().guarded_bodies;
        },
        &guarded);
    const Trajectory world = simulation.record();
    for (const TrajectoryObject& object : world.objects) {
      for (size_t f = 1; f < object.poses.size(); ++f) {
        fastest_step = std::max(fastest_step,
                                (object.poses[f].position - object.poses[f - 1].position).norm());
      }
    }
  }
  EXPECT_GT(fastest_step, 1.5 * model->config().graph.collision_radius);
  EXPECT_EQ(guarded, 0);
}

TEST(Stress, AFilterThatNamesNoCaseIsAnErrorNamingItAndTheGroups) {
  const std::string error = testing::error_of<ConfigError>([] {
    select_stress_cases({"stacks", "stakcs"}, 0.01, "--valid-stress");
  });
  EXPECT_NE(error.find("--valid-stress 'stakcs': no such case"), std::string::npos) << error;
  EXPECT_NE(error.find("the groups are canonical, rest, piles, stacks"), std::string::npos)
      << error;
}

// The cases run side by side give what each gives run alone, in the cases' order: Bullet, the
// network alone and the world (its Eigen setting left alone), pose for pose.
TEST(Stress, CasesRunSideBySideAsEachAlone) {
  auto model = std::make_shared<const Model>(
      load_model(std::string(FIGNET_SOURCE_DIR) + "/models/movi-a-small.h5"));
  const std::vector<Simulator> sims = stress_simulators({{"movi-a-small", model}}, 1, 0);
  const std::vector<StressCase> cases =
      select_stress_cases({"stack of 2", "one cube at rest", "canonical: cube dropped"}, 0.02);
  ASSERT_EQ(cases.size(), 4u);
  const auto together = run_stress_cases(cases, sims, 3);
  ASSERT_EQ(together.size(), cases.size());
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::vector<StressRun> alone = run_stress_case(cases[i], sims);
    ASSERT_EQ(together[i].size(), alone.size()) << cases[i].name;
    for (size_t s = 0; s < alone.size(); ++s) {
      const Trajectory& a = alone[s].trajectory;
      const Trajectory& b = together[i][s].trajectory;
      ASSERT_EQ(a.objects.size(), b.objects.size());
      for (size_t o = 0; o < a.objects.size(); ++o) {
        for (size_t f = 0; f < a.objects[o].poses.size(); ++f) {
          EXPECT_EQ(a.objects[o].poses[f].position, b.objects[o].poses[f].position)
              << cases[i].name << ", " << alone[s].simulator << ", frame " << f;
        }
      }
      EXPECT_EQ(together[i][s].drift, alone[s].drift) << cases[i].name;
    }
  }
}

}  // namespace
}  // namespace fignet::bullet
