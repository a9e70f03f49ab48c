// Generates a dataset of trajectories by simulating sampled scenes in native Bullet, in parallel.
// Trajectory i is simulated from its own seed (derived from the base seed and i alone), so the
// output is the same whatever the number of threads or shards.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "fignet/bullet/bullet_simulation.h"
#include "fignet/bullet/movi.h"
#include "fignet/io/trajectory_file.h"

namespace fignet::bullet {

struct GenerateOptions {
  MoviOptions scene;
  int count = 1;              // trajectories in the whole dataset
  std::uint64_t seed = 1;     // base seed
  int shard = 0, shards = 1;  // this process writes trajectories [count·shard/shards, …)
  int threads = 0;            // 0: every core
  SolverSettings solver;
};

// The seed of trajectory `index` of a dataset with base seed `seed` (splitmix64 of both).
std::uint64_t trajectory_seed(std::uint64_t seed, std::uint64_t index);

// Simulates this shard's trajectories; `done` (when given) counts finished ones for progress.
// Throws ConfigError for invalid options.
std::vector<Trajectory> generate_dataset(const GenerateOptions& options,
                                         std::atomic<int>* done = nullptr);

// What a file of this dataset records about how it was made (its attributes), so that every
// writer of generated data records the same fields. `generator_version`: the writing program's.
DatasetInfo dataset_info(const GenerateOptions& options, std::string generator_version);

}  // namespace fignet::bullet
