// `fignet graph-stats`: builds the input graph of a built-in scene and prints its size per node and
// edge type, with the mean build time.
#include <fmt/format.h>

#include <chrono>
#include <map>

#include "commands.h"
#include "fignet/data/trajectory.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/io/trajectory_file.h"
#include "fignet/scenes/resting_lattice.h"

namespace fignet::cli {

namespace {

struct GraphStatsOptions {
  std::string data;  // a trajectory file: statistics over its frames instead of the lattice
  int max_trajectories = 100;
  RestingLatticeOptions scene;
  GraphConfig graph;
  bool no_object_nodes = false;
  int repeat = 20;
};

// Mean edges per frame over the frames of a dataset (each frame's graph built as in training).
void run_dataset_stats(const GraphStatsOptions& options, const GraphConfig& config) {
  DatasetInfo info;
  const std::vector<Trajectory> data = read_trajectories(options.data, &info);
  GraphBuilder builder(config);
  Graph graph;
  Scene scene;
  double frames = 0, face_edges = 0, world_edges = 0, nodes = 0, objects = 0;
  const int count = std::min<int>(options.max_trajectories, static_cast<int>(data.size()));
  for (int i = 0; i < count; ++i) {
    for (int t = config.history; t < data[i].num_frames(); ++t) {
      scene_at_frame(data[i], t, config.history, scene);
      builder.build(scene, graph);
      frames += 1;
      face_edges += graph.face_edges.size();
      world_edges += graph.world_edges.size();
      nodes += graph.num_mesh_nodes();
      objects += static_cast<double>(scene.objects.size());
    }
  }
  fmt::print("{}: {} trajectories (preset {}), {} frames examined, collision radius {} m\n",
             options.data, count, info.preset, frames, config.collision_radius);
  fmt::print(
      "per frame: {:.1f} objects, {:.1f} mesh nodes (floor included), {:.1f} face-face edges, "
      "{:.1f} world edges\n",
      objects / frames, nodes / frames, face_edges / frames, world_edges / frames);
}

void run_graph_stats(const GraphStatsOptions& options) {
  GraphConfig config = options.graph;
  config.object_nodes = !options.no_object_nodes;
  if (!options.data.empty()) return run_dataset_stats(options, config);
  RestingLatticeOptions scene_options = options.scene;
  scene_options.history = config.history;
  const RestingLattice lattice = make_resting_lattice(scene_options);
  GraphBuilder builder(config);
  Graph graph;

  // The first build sizes every buffer; the timed ones reuse them, as a simulation step does.
  builder.build(lattice.scene, graph);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < options.repeat; ++i) builder.build(lattice.scene, graph);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  fmt::print("FIGNet input graph of a built-in scene: {} objects on a lattice above the floor\n",
             lattice.scene.objects.size());
  fmt::print("collision radius {} m, history {}, collisions {}, floor {}, object nodes {}\n\n",
             config.collision_radius, config.history,
             config.collisions == CollisionEdges::kFaceFace ? "face-face" : "node-node",
             config.floor == FloorModel::kMesh       ? "mesh"
             : config.floor == FloorModel::kImplicit ? "implicit"
                                                     : "none",
             config.object_nodes ? "on" : "off");
  fmt::print("{:<18} {:>8} {:>9}\n", "type", "count", "features");
  auto row = [](const char* name, int count, int features) {
    fmt::print("{:<18} {:>8} {:>9}\n", name, count, features);
  };
  row("mesh nodes", graph.num_mesh_nodes(), graph.mesh_nodes.cols());
  row("object nodes", graph.object_nodes.rows(), graph.object_nodes.cols());
  row("mesh edges", graph.mesh_edges.size(), graph.mesh_edges.features.cols());
  row("object->mesh", graph.object_to_mesh.size(), graph.object_to_mesh.features.cols());
  row("mesh->object", graph.mesh_to_object.size(), graph.mesh_to_object.features.cols());
  row("face-face edges", graph.face_edges.size(), graph.face_edges.features.cols());
  row("world edges", graph.world_edges.size(), graph.world_edges.features.cols());
  fmt::print("\ngraph built in {:.3f} ms (mean of {} builds, contact search included)\n",
             1e3 * seconds / std::max(1, options.repeat), options.repeat);
}

}  // namespace

void add_graph_stats_command(CLI::App& app) {
  auto options = std::make_shared<GraphStatsOptions>();
  auto* cmd = app.add_subcommand(
      "graph-stats", "Build the FIGNet input graph of a built-in scene and print its statistics");
  cmd->add_option(
      "--data", options->data,
      "Trajectory file: mean edges per frame over its frames instead of the built-in scene");
  cmd->add_option("--max-trajectories", options->max_trajectories,
                  "With --data: examine at most this many trajectories")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--objects", options->scene.objects, "Number of objects in the scene")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", options->scene.seed, "Random seed of the scene")->capture_default_str();
  cmd->add_option("--radius", options->graph.collision_radius, "Collision radius d_c in metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--history", options->graph.history, "Velocities in node features (h)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  const std::map<std::string, CollisionEdges> collisions = {{"face", CollisionEdges::kFaceFace},
                                                            {"node", CollisionEdges::kNodeNode}};
  cmd->add_option("--collisions", options->graph.collisions,
                  "face: face-face edges (FIGNet); node: node-node world edges (NoFaceCollision)")
      ->transform(CLI::CheckedTransformer(collisions, CLI::ignore_case));
  const std::map<std::string, FloorModel> floors = {{"mesh", FloorModel::kMesh},
                                                    {"implicit", FloorModel::kImplicit},
                                                    {"none", FloorModel::kNone}};
  cmd->add_option("--floor", options->graph.floor, "Floor model: mesh, implicit or none")
      ->transform(CLI::CheckedTransformer(floors, CLI::ignore_case));
  cmd->add_flag("--no-object-nodes", options->no_object_nodes,
                "Drop object nodes (the FIGNet-NoObjectNode ablation)");
  cmd->add_option("--repeat", options->repeat, "Timed builds after the first")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->callback([options] { run_graph_stats(*options); });
}

}  // namespace fignet::cli
