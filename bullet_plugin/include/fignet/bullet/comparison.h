// The side-by-side with native Bullet: the same scenes, built once by the shared scene code,
// stepped by native Bullet at 240 Hz (the ground truth), by FIGNetDynamicsWorld with each model,
// by native Bullet at coarser settings, and by native Bullet from initial positions perturbed by
// 1e-6 m (the chaos floor: how far two runs of the same simulator drift apart on their own).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/fignet_dynamics_world.h"
#include "fignet/model/model.h"
#include "fignet/rollout/metrics.h"

namespace fignet::bullet {

// The scene a recorded trajectory started from: its meshes, masses (inertia from the mesh at the
// mass's density), materials, floor, first poses and first velocities, kinematic scripts.
SceneSpec scene_from_trajectory(const Trajectory& trajectory);

struct ComparisonRun {
  std::string name;  // e.g. "Bullet 48 Hz"
  std::string kind;  // "ground truth", "FIGNet", "Bullet", "chaos floor"
  SolverSettings settings;
  std::shared_ptr<const Model> model;  // set: a FIGNetDynamicsWorld with this model
  double perturbation = 0.0;           // metres, random direction per dynamic body
  FIGNetWorldOptions world_options;    // for model runs
};

// The name of Bullet stepped once per frame, the model's own step: the cheap native setting a
// learned simulator is set against.
inline constexpr const char* kCoarseBulletRun = "Bullet 48 Hz";

// Ground truth first, then one run per model, Bullet at 48 Hz, Bullet at 240 Hz with 2 solver
// iterations, and the chaos floor. `model_names` label the models (file names).
std::vector<ComparisonRun> standard_runs(const std::vector<std::shared_ptr<const Model>>& models,
                                         const std::vector<std::string>& model_names);

struct RunResult {
  ComparisonRun run;
  std::vector<Trajectory> trajectories;       // one per scene
  std::vector<RolloutErrors> errors;          // against the ground truth, per scene
  std::vector<double> translation, rotation;  // per frame, mean over scenes
  double mean_translation = 0, final_translation = 0, mean_rotation = 0, final_rotation = 0;
  double seconds = 0;  // wall time stepping every scene
  double milliseconds_per_simulated_second = 0;
};

// Runs every run on every scene (runs[0] is the ground truth the others are measured against).
// `on_progress(run, scene)` is called after each.
std::vector<RunResult> compare_runs(const std::vector<SceneSpec>& scenes,
                                    const std::vector<ComparisonRun>& runs,
                                    const std::function<void(int, int)>& on_progress = {});

}  // namespace fignet::bullet
