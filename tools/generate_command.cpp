// `fignet generate`: simulates Kubric-style scenes in Bullet and writes a trajectory file.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <regex>
#include <thread>

#include "commands.h"
#include "fignet/bullet/dataset_generator.h"
#include "fignet/error.h"
#include "fignet/io/trajectory_file.h"
#include "progress.h"

#ifndef FIGNET_VERSION
#define FIGNET_VERSION "unknown"
#endif

namespace fignet::cli {

namespace {

struct GenerateArgs {
  bullet::GenerateOptions options;
  std::string mesh_inertia = "auto";
  bool no_repair = false;
  std::string shard = "0/1";
  std::filesystem::path out;
};

void run_generate(GenerateArgs args) {
  std::smatch match;
  const std::regex shard_pattern(R"((\d+)/(\d+))");
  if (!std::regex_match(args.shard, match, shard_pattern)) {
    throw ConfigError(fmt::format("--shard '{}' must look like i/N (for example 0/4)", args.shard));
  }
  args.options.scene.mesh_import.inertia = bullet::parse_mesh_inertia(args.mesh_inertia);
  args.options.scene.mesh_import.repair = !args.no_repair;
  args.options.shard = std::stoi(match[1]);
  args.options.shards = std::stoi(match[2]);
  const auto parent = args.out.parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw FileError(
        fmt::format("--out '{}': folder '{}' does not exist", args.out.string(), parent.string()));
  }
  const int total = static_cast<int>(
      static_cast<long long>(args.options.count) * (args.options.shard + 1) / args.options.shards -
      static_cast<long long>(args.options.count) * args.options.shard / args.options.shards);
  std::atomic<int> done{0};
  const auto start = std::chrono::steady_clock::now();
  auto future =
      std::async(std::launch::async, [&] { return bullet::generate_dataset(args.options, &done); });
  ProgressBar bar("generate", total);
  while (future.wait_for(std::chrono::milliseconds(200)) != std::future_status::ready) {
    bar.update(done);
  }
  const std::vector<Trajectory> trajectories = future.get();
  bar.finish(total);
  write_trajectories(args.out, trajectories, bullet::dataset_info(args.options, FIGNET_VERSION));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("wrote {} trajectories ({} frames each) to {} in {:.1f} s\n", trajectories.size(),
             trajectories.front().num_frames(), args.out.string(), seconds);
}

}  // namespace

void add_generate_command(CLI::App& app) {
  auto args = std::make_shared<GenerateArgs>();
  auto* cmd = app.add_subcommand(
      "generate", "Simulate Kubric-style scenes in Bullet and write a trajectory file");
  cmd->add_option("--preset", args->options.scene.preset, "Scene preset")
      ->check(CLI::IsMember(bullet::movi_presets()))
      ->capture_default_str();
  cmd->add_option("--count", args->options.count, "Trajectories in the whole dataset")
      ->check(CLI::Range(1, 10'000'000))
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed,
                  "Base seed (use different seeds for train/valid/test)")
      ->capture_default_str();
  cmd->add_option("--frames", args->options.scene.frames,
                  "Frames per trajectory (0: the preset's, movi-a 96 at 48 Hz, pushing 42)")
      ->check(CLI::Range(0, 100'000))
      ->capture_default_str();
  cmd->add_option("--min-objects", args->options.scene.min_objects,
                  "Fewest tossed objects per scene (at least 1 without --stacks or --piles)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  cmd->add_option("--max-objects", args->options.scene.max_objects, "Most tossed objects per scene")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  CLI::Option* stacks =
      cmd->add_option(
             "--stacks", args->options.scene.stacks,
             "Stacks of cubes and upright cylinders standing still on the floor of each "
             "movi-a or movi-b scene, placed before the tossed objects (--min-objects may then "
             "be 0); 0: the preset's own scenes")
          ->check(CLI::Range(0, 20))
          ->capture_default_str();
  cmd->add_option("--min-stack-levels", args->options.scene.min_stack_levels,
                  "Fewest levels per stack (with --stacks)")
      ->needs(stacks)
      ->check(CLI::Range(1, bullet::kMaxStackLevels))
      ->capture_default_str();
  cmd->add_option("--max-stack-levels", args->options.scene.max_stack_levels,
                  "Most levels per stack (with --stacks); the levels are uniform in the range")
      ->needs(stacks)
      ->check(CLI::Range(1, bullet::kMaxStackLevels))
      ->capture_default_str();
  cmd->add_option("--sphere-topped-stacks", args->options.scene.sphere_topped_stacks,
                  "Share of the stacks (0-1) topped with a MOVi sphere resting still on one of its "
                  "facets (with --stacks); 0: none")
      ->needs(stacks)
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  CLI::Option* piles =
      cmd->add_option("--piles", args->options.scene.piles,
                      "Piles of the preset's objects dropped in a column and settled by Bullet "
                      "before the first frame, still on the floor of each movi-a or movi-b "
                      "scene, placed after the stacks and before the tossed objects (--min-objects "
                      "may then be 0); 0: none")
          ->check(CLI::Range(0, 20))
          ->capture_default_str();
  cmd->add_option("--min-pile-objects", args->options.scene.min_pile_objects,
                  "Fewest objects per pile (with --piles)")
      ->needs(piles)
      ->check(CLI::Range(1, bullet::kMaxPileObjects))
      ->capture_default_str();
  cmd->add_option("--max-pile-objects", args->options.scene.max_pile_objects,
                  "Most objects per pile (with --piles); the counts are uniform in the range")
      ->needs(piles)
      ->check(CLI::Range(1, bullet::kMaxPileObjects))
      ->capture_default_str();
  cmd->add_option("--assets", args->options.scene.assets,
                  "Folder of mesh files (OBJ, STL, PLY, glTF, OFF): extra objects for movi-b, the "
                  "only objects of movi-c; open and messy meshes are repaired (one warning line "
                  "each says what was done)");
  bullet::MeshImportOptions& mesh = args->options.scene.mesh_import;
  cmd->add_option("--mesh-inertia", args->mesh_inertia,
                  "Asset mass and inertia: auto (volume if closed, else convex hull), volume, "
                  "convex or shell (density per m² of surface)")
      ->check(CLI::IsMember({"auto", "volume", "convex", "shell"}))
      ->capture_default_str();
  cmd->add_option("--graph-vertices", mesh.max_graph_vertices,
                  "Assets with more vertices are simplified for the graph (0: never)")
      ->check(CLI::Range(0, 100'000'000))
      ->capture_default_str();
  cmd->add_option("--simplify-tolerance", mesh.simplify_tolerance,
                  "Largest deviation of a simplified asset, as a fraction of its largest side")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  cmd->add_flag("--no-repair", args->no_repair,
                "Give FIGNet open assets as they are instead of a closed alpha wrap");
  cmd->add_option("--threads", args->options.threads, "Worker threads (0: every core)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_option("--shard", args->shard, "Write shard i of N (i/N) so machines can split the work")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "Output file (.h5), written atomically")->required();
  cmd->callback([args] { run_generate(*args); });
}

}  // namespace fignet::cli
