#include "fignet/bullet/comparison.h"

#include <fmt/format.h>

#include <chrono>
#include <random>

#include "fignet/bullet/convex_decomposition.h"
#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/error.h"
#include "fignet/geometry/mass_properties.h"
#include "fignet/rollout/evaluation.h"

namespace fignet::bullet {

SceneSpec scene_from_trajectory(const Trajectory& trajectory) {
  trajectory.validate();
  SceneSpec spec;
  spec.floor = trajectory.floor;
  spec.gravity = trajectory.gravity;
  spec.seed = trajectory.seed;
  spec.frames = trajectory.num_frames();
  // Bullet at 240 Hz (or the nearest whole number of steps per frame).
  spec.steps_per_frame = std::max(1, static_cast<int>(std::lround(trajectory.time_step * 240.0)));
  spec.physics_step = trajectory.time_step / spec.steps_per_frame;
  for (const TrajectoryObject& object : trajectory.objects) {
    BodySpec body;
    if (object.inertia) {
      // Recorded inertia: the mesh's frame is the body's, whatever the mesh's own volume says.
      const std::vector<Points> parts = collision_parts(*object.mesh);
      body.convex_parts = parts.size() > 1 ? parts : std::vector<Points>{};
      body.inertia = *object.inertia;
    } else {
      // Older files: the uniform-density inertia of the mesh, which is already in its principal
      // frame.
      const double volume = compute_mass_properties(*object.mesh).volume;
      const double density = object.kinematic ? 1.0 : object.properties.mass / volume;
      body = make_body(*object.mesh, density, object.properties.friction,
                       object.properties.restitution, collision_parts(*object.mesh));
    }
    // The rest mesh is already in the body's frame: keep the recorded mesh itself.
    body.mesh = object.mesh;
    body.properties = object.properties;
    body.kinematic = object.kinematic;
    body.pose = object.poses.front();
    if (!object.linear_velocities.empty()) {
      body.linear_velocity = object.linear_velocities.front();
      body.angular_velocity = object.angular_velocities.front();
    } else if (object.poses.size() > 1) {
      body.linear_velocity =
          (object.poses[1].position - object.poses[0].position) / trajectory.time_step;
    }
    spec.bodies.push_back(std::move(body));
  }
  return spec;
}

std::vector<ComparisonRun> standard_runs(const std::vector<std::shared_ptr<const Model>>& models,
                                         const std::vector<std::string>& model_names) {
  if (models.size() != model_names.size()) {
    throw ConfigError("standard_runs: one name per model");
  }
  std::vector<ComparisonRun> runs;
  runs.push_back({"Bullet 240 Hz", "ground truth", {}, nullptr, 0.0, {}});
  for (size_t i = 0; i < models.size(); ++i) {
    SolverSettings one_step_per_frame;
    one_step_per_frame.steps_per_frame = 1;
    // The network alone (the model's own accuracy), then the world as users get it (free
    // flight, sleeping, the penetration, rest and energy guards).
    runs.push_back({fmt::format("FIGNet {}, network alone", model_names[i]), "FIGNet",
                    one_step_per_frame, models[i], 0.0, FIGNetWorldOptions::network_alone()});
    runs.push_back({fmt::format("FIGNet {}", model_names[i]), "FIGNet", one_step_per_frame,
                    models[i], 0.0, FIGNetWorldOptions{}});
  }
  SolverSettings coarse;
  coarse.steps_per_frame = 1;
  runs.push_back({kCoarseBulletRun, "Bullet", coarse, nullptr, 0.0, {}});
  SolverSettings few_iterations;
  few_iterations.iterations = 2;
  runs.push_back({"Bullet 240 Hz, 2 iterations", "Bullet", few_iterations, nullptr, 0.0, {}});
  runs.push_back({"Bullet 240 Hz, start moved 1e-6 m", "chaos floor", {}, nullptr, 1e-6, {}});
  return runs;
}

namespace {

SceneSpec perturbed(SceneSpec spec, double distance) {
  std::mt19937_64 rng(spec.seed ^ 0x5eedc4a05ULL);
  std::normal_distribution<double> normal;
  for (BodySpec& body : spec.bodies) {
    if (body.kinematic) continue;
    const Vec3 direction = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    body.pose.position += distance * direction;
  }
  return spec;
}

WorldFactory world_for(const ComparisonRun& run) {
  if (!run.model) return {};
  std::shared_ptr<const Model> model = run.model;
  const FIGNetWorldOptions options = run.world_options;
  return [model, options](btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                          btConstraintSolver* solver, btCollisionConfiguration* configuration) {
    return std::make_unique<FIGNetDynamicsWorld>(dispatcher, broadphase, solver, configuration,
                                                 model, options);
  };
}

// Per-frame means over scenes and the summary means: `fignet eval`'s summary of the same errors.
void summarise(RunResult& result) {
  EvaluationTotals totals;
  totals.per_trajectory = result.errors;
  const Evaluation e = summarize(totals);
  result.translation = e.translation;
  result.rotation = e.rotation;
  result.mean_translation = e.mean_translation;
  result.final_translation = e.final_translation;
  result.mean_rotation = e.mean_rotation;
  result.final_rotation = e.final_rotation;
}

}  // namespace

std::vector<RunResult> compare_runs(const std::vector<SceneSpec>& scenes,
                                    const std::vector<ComparisonRun>& runs,
                                    const std::function<void(int, int)>& on_progress) {
  if (scenes.empty()) throw ConfigError("compare_runs: no scene");
  if (runs.empty()) throw ConfigError("compare_runs: no run");
  std::vector<RunResult> results;
  for (size_t r = 0; r < runs.size(); ++r) {
    RunResult result;
    result.run = runs[r];
    double simulated = 0.0;
    for (size_t s = 0; s < scenes.size(); ++s) {
      const SceneSpec spec =
          runs[r].perturbation > 0 ? perturbed(scenes[s], runs[r].perturbation) : scenes[s];
      const auto start = std::chrono::steady_clock::now();
      BulletSimulation simulation(spec, runs[r].settings, world_for(runs[r]));
      result.trajectories.push_back(simulation.record());
      result.seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      simulated += (spec.frames - 1) * spec.frame_step();
      if (on_progress) on_progress(static_cast<int>(r), static_cast<int>(s));
    }
    result.milliseconds_per_simulated_second = 1e3 * result.seconds / simulated;
    const std::vector<Trajectory>& truth = r == 0 ? result.trajectories : results[0].trajectories;
    for (size_t s = 0; s < scenes.size(); ++s) {
      result.errors.push_back(rollout_errors(result.trajectories[s], truth[s], 1));
    }
    summarise(result);
    results.push_back(std::move(result));
  }
  return results;
}

}  // namespace fignet::bullet
