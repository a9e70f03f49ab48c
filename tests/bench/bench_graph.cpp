// Graph construction (contact search included) for resting-lattice scenes of 6, 100 and 1000
// MOVi-A objects at the same density. Cost should grow about linearly with objects and contacts:
// compare the per_object counters of the 100- and 1000-object runs.
//
//   build/release/tests/bench/bench_graph
#include <benchmark/benchmark.h>

#include "fignet/graph/graph_builder.h"
#include "fignet/scenes/resting_lattice.h"

namespace fignet {
namespace {

void BM_BuildGraph(benchmark::State& state) {
  RestingLatticeOptions options;
  options.objects = static_cast<int>(state.range(0));
  options.seed = 1;
  const RestingLattice lattice = make_resting_lattice(options);
  GraphBuilder builder(GraphConfig{});
  Graph graph;
  builder.build(lattice.scene, graph);  // sizes the buffers, as the first simulation step does
  for (auto _ : state) {
    builder.build(lattice.scene, graph);
    benchmark::DoNotOptimize(graph.face_edges.features.row(0));
  }
  state.counters["mesh_nodes"] = graph.num_mesh_nodes();
  state.counters["face_edges"] = graph.face_edges.size();
  state.counters["per_object"] = benchmark::Counter(
      static_cast<double>(options.objects),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_BuildGraph)->Arg(6)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

void BM_BuildGraphNodeNode(benchmark::State& state) {
  RestingLatticeOptions options;
  options.objects = static_cast<int>(state.range(0));
  options.seed = 1;
  const RestingLattice lattice = make_resting_lattice(options);
  GraphConfig config;
  config.collisions = CollisionEdges::kNodeNode;
  config.floor = FloorModel::kImplicit;
  GraphBuilder builder(config);
  Graph graph;
  builder.build(lattice.scene, graph);
  for (auto _ : state) builder.build(lattice.scene, graph);
  state.counters["world_edges"] = graph.world_edges.size();
}
BENCHMARK(BM_BuildGraphNodeNode)->Arg(6)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace fignet

BENCHMARK_MAIN();
