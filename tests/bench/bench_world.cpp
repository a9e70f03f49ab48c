// FIGNetDynamicsWorld against native Bullet on the same scenes, in the same run: the whole step
// with a model, the world's own cost with a network-free predictor (conversion, broadphase, face
// pairs, write-back), a few bodies on a large static triangle mesh, and a few bodies in contact
// among many in free flight or asleep.
//
//   build/release/tests/bench/bench_world
#include <benchmark/benchmark.h>

#include <random>

#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/conversions.h"
#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/bullet/movi.h"

namespace fignet::bullet {
namespace {

// `count` MOVi-A objects on a grid above the floor, so every body is in play.
SceneSpec grid_scene(int count) {
  SceneSpec spec = sample_movi_scene({}, 7);
  const BodySpec prototype = spec.bodies.front();
  spec.bodies.clear();
  const int side = static_cast<int>(std::ceil(std::sqrt(count)));
  for (int i = 0; i < count; ++i) {
    BodySpec body = sample_movi_scene({}, 100 + i).bodies.front();
    body.pose.position = Vec3(3.5 * (i % side), 3.5 * (i / side), 1.6);
    body.linear_velocity.setZero();
    spec.bodies.push_back(body);
  }
  return spec;
}

// The network alone (no free flight, sleep or guard): every body goes through the predictor at
// every frame, so these measure what the network and the world's own work cost per body.
WorldFactory fignet_world(std::shared_ptr<const Model> model) {
  return [model](btDispatcher* d, btBroadphaseInterface* b, btConstraintSolver* s,
                 btCollisionConfiguration* c) {
    return std::make_unique<FIGNetDynamicsWorld>(d, b, s, c, model,
                                                 FIGNetWorldOptions::network_alone());
  };
}

WorldFactory gravity_world() {
  return [](btDispatcher* d, btBroadphaseInterface* b, btConstraintSolver* s,
            btCollisionConfiguration* c) {
    return std::make_unique<FIGNetDynamicsWorld>(
        d, b, s, c, std::make_unique<GravityPredictor>(Vec3(0, 0, -10), 1.0 / 48.0), GraphConfig{},
        1.0 / 48.0, Vec3(0, 0, -10), FIGNetWorldOptions::network_alone());
  };
}

// One 48 Hz frame per iteration: native Bullet takes 5 steps at 240 Hz, FIGNet one.
void run_frames(benchmark::State& state, const SceneSpec& spec, const SolverSettings& settings,
                const WorldFactory& factory) {
  BulletSimulation simulation(spec, settings, factory);
  for (auto _ : state) simulation.step_frame();
  state.counters["bodies"] = static_cast<double>(spec.bodies.size());
  state.SetLabel("per 48 Hz frame");
}

void NativeBullet240Hz(benchmark::State& state) {
  run_frames(state, grid_scene(static_cast<int>(state.range(0))), {}, {});
}

void FIGNetWorldOutsideTheNetwork(benchmark::State& state) {
  SolverSettings settings;
  settings.steps_per_frame = 1;
  run_frames(state, grid_scene(static_cast<int>(state.range(0))), settings, gravity_world());
}

// The whole step with an untrained model of the named preset (the cost does not depend on the
// weights): "small" (what models/ ships) and "paper" (the seed's 10 message-passing steps, 128
// latent).
void FIGNetWorldWithModel(benchmark::State& state, const char* preset) {
  SolverSettings settings;
  settings.steps_per_frame = 1;
  auto model = std::make_shared<const Model>(ModelConfig::preset_named(preset));
  run_frames(state, grid_scene(static_cast<int>(state.range(0))), settings, fignet_world(model));
}

BENCHMARK(NativeBullet240Hz)->Arg(10)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(FIGNetWorldOutsideTheNetwork)->Arg(10)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(FIGNetWorldWithModel, small, "small")
    ->Arg(10)
    ->Arg(100)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(FIGNetWorldWithModel, paper, "paper")
    ->Arg(10)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond);

// A few bodies on a static triangle mesh of n×n half-metre squares: the world's cost should not
// grow with n, since only the triangles near the bodies enter the graph.
void FIGNetWorldOnALargeStaticMesh(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  FIGNetDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration,
                            std::make_unique<GravityPredictor>(Vec3(0, 0, -10), 1.0 / 48.0),
                            GraphConfig{}, 1.0 / 48.0, Vec3(0, 0, -10));
  btTriangleMesh terrain;
  const float size = 0.5f, corner = -0.25f * n;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const btVector3 a(corner + i * size, corner + j * size, 0), b = a + btVector3(size, 0, 0),
                                                                  c = a + btVector3(size, size, 0),
                                                                  d = a + btVector3(0, size, 0);
      terrain.addTriangle(a, b, c);
      terrain.addTriangle(a, c, d);
    }
  }
  btBvhTriangleMeshShape ground(&terrain, true);
  btRigidBody floor(0, nullptr, &ground);
  world.addRigidBody(&floor);
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  btBoxShape box(btVector3(0.5f, 0.5f, 0.5f));
  for (int k = 0; k < 3; ++k) {
    btVector3 inertia;
    box.calculateLocalInertia(1, inertia);
    bodies.push_back(std::make_unique<btRigidBody>(1, nullptr, &box, inertia));
    bodies.back()->setWorldTransform(
        btTransform(btQuaternion::getIdentity(), btVector3(3.0f * k, 0, 0.55f)));
    bodies.back()->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(bodies.back().get());
  }
  for (auto _ : state) {
    // Hold the boxes just above the mesh so every step sees the same contacts.
    for (int k = 0; k < 3; ++k) {
      bodies[k]->setWorldTransform(
          btTransform(btQuaternion::getIdentity(), btVector3(3.0f * k, 0, 0.55f)));
      bodies[k]->setLinearVelocity(btVector3(0, 0, 0));
    }
    world.stepSimulation(1.0f / 48.0f, 1, 1.0f / 48.0f);
  }
  state.counters["mesh_triangles"] = 2.0 * n * n;
  state.counters["graph_objects"] = world.last_step_stats().kinematic_objects;
  for (auto& body : bodies) world.removeRigidBody(body.get());
  world.removeRigidBody(&floor);
}
BENCHMARK(FIGNetWorldOnALargeStaticMesh)
    ->Arg(10)
    ->Arg(100)
    ->Arg(400)
    ->Unit(benchmark::kMicrosecond);

// What the bodies besides those in contact do.
enum class Others { kInFreeFlight, kAsleep, kAtRest };

// Cost follows contact, not scene size: `in_contact` boxes 1 cm above the floor (within the
// collision radius, outside the rest guard's 5 mm: the network's work) among `total` bodies whose
// others are in free flight high above it, asleep on it, or awake and resting on it (the rest
// guard keeps them out of the network), far apart. Every iteration puts the moving bodies back,
// so each step sees the same contacts. Model: the small preset, untrained (the cost does not
// depend on the weights).
void FIGNetWorldMostlyIdle(benchmark::State& state, Others others) {
  const bool others_asleep = others == Others::kAsleep;
  const int total = static_cast<int>(state.range(0));
  const int in_contact = static_cast<int>(state.range(1));
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  auto model = std::make_shared<const Model>(ModelConfig::preset_named("small"));
  FIGNetDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration,
                            std::make_unique<ModelPredictor>(model), model->config().graph,
                            1.0 / 48.0, Vec3(0, 0, -10));
  btStaticPlaneShape plane(btVector3(0, 0, 1), 0);
  btRigidBody floor(0, nullptr, &plane);
  world.addRigidBody(&floor);
  btBoxShape box(btVector3(0.2f, 0.2f, 0.2f));
  btVector3 inertia;
  box.calculateLocalInertia(1, inertia);
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<btTransform> starts;
  const int side = static_cast<int>(std::ceil(std::sqrt(total)));
  for (int i = 0; i < total; ++i) {
    const bool contact = i < in_contact;
    const btVector3 grid(3.0f * (i % side) + 20, 3.0f * (i / side) + 20, 0);
    // Contact bodies 1 m apart near the origin: the model's floor mesh spans ±40 m.
    const int row = static_cast<int>(std::ceil(std::sqrt(in_contact)));
    const btVector3 start = contact ? btVector3(1.0f * (i % row) - 15, 1.0f * (i / row) - 15, 0.21f)
                            : others == Others::kInFreeFlight ? grid + btVector3(0, 0, 50)
                                                              : grid + btVector3(0, 0, 0.2f);
    bodies.push_back(std::make_unique<btRigidBody>(1, nullptr, &box, inertia));
    starts.emplace_back(btQuaternion::getIdentity(), start);
    bodies.back()->setWorldTransform(starts.back());
    world.addRigidBody(bodies.back().get());
    // Put back at rest every step, the moving bodies would fall asleep after Bullet's 2 s.
    bodies.back()->setActivationState(!contact && others_asleep ? ISLAND_SLEEPING
                                                                : DISABLE_DEACTIVATION);
  }
  for (auto _ : state) {
    for (int i = 0; i < total; ++i) {
      if (!bodies[i]->isActive()) continue;
      bodies[i]->setWorldTransform(starts[i]);
      bodies[i]->setLinearVelocity(btVector3(0, 0, 0));
      bodies[i]->setAngularVelocity(btVector3(0, 0, 0));
    }
    world.stepSimulation(1.0f / 48.0f, 1, 1.0f / 48.0f);
  }
  const FIGNetStepStats& stats = world.last_step_stats();
  state.counters["network_bodies"] = stats.simulated_bodies;
  state.counters["free_flight"] = stats.free_flight_bodies;
  state.counters["asleep"] = stats.sleeping_bodies;
  state.counters["at_rest"] = stats.rested_bodies;
  state.counters["face_edges"] = stats.face_edges;
  state.counters["pairs"] = stats.candidate_pairs;
  for (auto& body : bodies) world.removeRigidBody(body.get());
  world.removeRigidBody(&floor);
}
BENCHMARK_CAPTURE(FIGNetWorldMostlyIdle, others_in_free_flight, Others::kInFreeFlight)
    ->Args({10, 10})
    ->Args({100, 10})
    ->Args({1000, 10})
    ->Args({100, 100})
    ->Args({1000, 1000})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(FIGNetWorldMostlyIdle, others_asleep, Others::kAsleep)
    ->Args({100, 10})
    ->Args({1000, 10})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(FIGNetWorldMostlyIdle, others_at_rest, Others::kAtRest)
    ->Args({100, 10})
    ->Args({1000, 10})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace fignet::bullet

BENCHMARK_MAIN();
