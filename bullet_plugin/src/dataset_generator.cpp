#include "fignet/bullet/dataset_generator.h"

#include <fmt/format.h>

#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "fignet/error.h"

namespace fignet::bullet {

std::uint64_t trajectory_seed(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + index + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::vector<Trajectory> generate_dataset(const GenerateOptions& options, std::atomic<int>* done) {
  if (options.count < 1) throw ConfigError(fmt::format("count = {} (must be >= 1)", options.count));
  if (options.shards < 1 || options.shard < 0 || options.shard >= options.shards) {
    throw ConfigError(fmt::format("shard {}/{} is not one of 0..{} of {}", options.shard,
                                  options.shards, options.shards - 1, options.shards));
  }
  sample_scene(options.scene, 0);  // validates the scene options before any thread starts
  const int begin =
      static_cast<int>(static_cast<long long>(options.count) * options.shard / options.shards);
  const int end = static_cast<int>(static_cast<long long>(options.count) * (options.shard + 1) /
                                   options.shards);
  std::vector<Trajectory> result(end - begin);
  const int threads = std::max(
      1, std::min<int>(options.threads > 0 ? options.threads : std::thread::hardware_concurrency(),
                       end - begin));
  std::atomic<int> next{begin};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&] {
    for (int i = next++; i < end; i = next++) {
      try {
        const SceneSpec spec = sample_scene(options.scene, trajectory_seed(options.seed, i));
        BulletSimulation simulation(spec, options.solver);
        result[i - begin] = simulation.record();
      } catch (...) {
        const std::lock_guard lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = end;
      }
      if (done) ++*done;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& thread : pool) thread.join();
  if (failure) std::rethrow_exception(failure);
  return result;
}

DatasetInfo dataset_info(const GenerateOptions& options, std::string generator_version) {
  return {.preset = options.scene.preset,
          .generator_version = std::move(generator_version),
          .seed = options.seed,
          .stacks = options.scene.stacks,
          .min_stack_levels = options.scene.min_stack_levels,
          .max_stack_levels = options.scene.max_stack_levels,
          .piles = options.scene.piles,
          .min_pile_objects = options.scene.min_pile_objects,
          .max_pile_objects = options.scene.max_pile_objects,
          .sphere_topped_stacks = options.scene.sphere_topped_stacks};
}

}  // namespace fignet::bullet
