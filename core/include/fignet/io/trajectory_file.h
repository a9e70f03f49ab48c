// Trajectory files: versioned HDF5 holding many trajectories with their rest meshes, static
// properties, kinematic flags, floor, and per-frame poses and velocities (schema in
// docs/trajectory-file.md; readable with h5py). Written by `fignet generate`, read by training and
// evaluation.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fignet/data/trajectory.h"

namespace fignet {

inline constexpr long long kTrajectoryFileVersion = 1;

// Describes how a file's trajectories were made.
struct DatasetInfo {
  std::string preset;             // e.g. "movi-a"
  std::string generator_version;  // the generating program's version
  std::uint64_t seed = 0;         // the generator's base seed
  int stacks = 0;                 // stacks at rest per scene (generate --stacks); 0: the preset's
  int min_stack_levels = 1, max_stack_levels = 3;  // levels per stack (generate --*-stack-levels)
  int piles = 0;  // settled piles at rest per scene (generate --piles)
  int min_pile_objects = 3, max_pile_objects = 6;  // objects per pile (generate --*-pile-objects)
  double sphere_topped_stacks = 0.0;  // share of stacks a sphere tops (--sphere-topped-stacks)

  bool operator==(const DatasetInfo&) const = default;
};

// Writes to a temporary file beside `path`, then renames it into place. Throws FileError.
void write_trajectories(const std::filesystem::path& path, std::span<const Trajectory> trajectories,
                        const DatasetInfo& info);

// Reads every trajectory of one file; throws FileError naming the file and what is wrong.
std::vector<Trajectory> read_trajectories(const std::filesystem::path& path,
                                          DatasetInfo* info = nullptr);
// Reads several files (shards) in order, concatenated.
std::vector<Trajectory> read_trajectories(const std::vector<std::filesystem::path>& paths);

// One process's share of several files: of the trajectories in order, every `count`-th from the
// `index`-th; the others are skipped unread (data-parallel training).
struct TrajectoryShare {
  int index = 0, count = 1;
};
std::vector<Trajectory> read_trajectories(const std::vector<std::filesystem::path>& paths,
                                          const TrajectoryShare& share);

}  // namespace fignet
