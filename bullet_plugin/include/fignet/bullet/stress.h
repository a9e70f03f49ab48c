// The stress suite: scenes at the extremes (long rests, stacks, sizes and densities far from
// training, impacts faster than the collision radius per step, far from the origin, long
// rollouts, odd meshes), each run by native Bullet at 240 Hz and by a FIGNet world, with what goes
// wrong measured the same way for both.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "fignet/bullet/bullet_simulation.h"
#include "fignet/model/model.h"

namespace fignet::bullet {

struct StressCase {
  std::string name, group;  // e.g. "impact 50 m/s", "speed"
  SceneSpec scene;
  bool at_rest = false;       // started at rest: drift and late speed are failures
  bool compare = true;        // error against Bullet at 240 Hz is meaningful (not chaotic)
  Vec3 shift = Vec3::Zero();  // a "far from the origin" case: metres it was moved by
};

// Every case, each `frames` long where the issue fixes no length (0: the cases' own lengths).
// `scale_frames` < 1 shortens the long cases for quick runs and tests.
std::vector<StressCase> stress_cases(double scale_frames = 1.0);

// The cases for which `keep(name, group)` holds, in the suite's order. Only kept scenes are built:
// the piles are settled by Bullet first (about a second each, the 100-object pile much longer).
std::vector<StressCase> stress_cases(
    double scale_frames,
    const std::function<bool(std::string_view name, std::string_view group)>& keep);

// The cases named by `filters`, in the suite's order: a case is kept when its name contains one
// of them or its group is one (every case for no filter). A filter that matches nothing is a
// ConfigError naming it and the `option` it came from, so a misspelt case fails before a long
// run (and before any pile is settled), not after. Only the kept cases' scenes are built.
std::vector<StressCase> select_stress_cases(const std::vector<std::string>& filters,
                                            double scale_frames = 1.0,
                                            std::string_view option = "--case");

struct StressRun {
  std::string simulator;
  bool finite = true;          // no NaN or inf in any pose
  double lowest = 0.0;         // lowest vertex relative to the floor over the run, metres
  double drift = 0.0;          // at_rest cases: largest centre displacement at the end, metres
  double drift_degrees = 0.0;  // … and rotation
  double late_speed = 0.0;     // largest body speed over the last half of the run, m/s
  double error = 0.0;          // mean translation error against Bullet 240 Hz, metres
  // at_rest cases: the largest drop of a body over the first frame, as a fraction of free fall
  // from rest (|g|·dt²): 0 where the simulator holds it, 1 where nothing does, below 0 where it
  // lifts. One step, from the same start every time: unlike drift, not chaotic.
  double first_step_fall = 0.0;
  double milliseconds_per_frame = 0.0;
  Trajectory trajectory;
};

struct Simulator {
  std::string name;
  SolverSettings settings;
  WorldFactory make_world;  // none: native Bullet
};

// Native Bullet at 240 Hz and, per model, a FIGNet world stepping once per frame: the network
// alone, then the world as users get it, both averaging over `turns` headings
// (FIGNetWorldOptions::turns), and with `mirror` over their mirror images too. `world_threads` is
// each world's FIGNetWorldOptions::threads: 0 leaves Eigen's process-wide setting alone, as
// worlds run side by side must.
std::vector<Simulator> stress_simulators(
    const std::vector<std::pair<std::string, std::shared_ptr<const Model>>>& models, int turns = 1,
    int world_threads = 1, bool mirror = false);

// Runs one case on each simulator (the first is the reference for `error`).
std::vector<StressRun> run_stress_case(const StressCase& c, const std::vector<Simulator>& sims);

// run_stress_case for every case, the cases shared among `threads` (the longest started first),
// the results in the cases' order. The simulators' worlds should have world_threads 0 when
// `threads` > 1; each run's milliseconds_per_frame then counts a core shared with the others.
std::vector<std::vector<StressRun>> run_stress_cases(const std::vector<StressCase>& cases,
                                                     const std::vector<Simulator>& sims,
                                                     int threads);

}  // namespace fignet::bullet
