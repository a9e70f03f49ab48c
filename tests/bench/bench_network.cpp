// FIGNet inference and training steps on a 6-object MOVi-A-like scene (~400 mesh nodes), for the
// "paper" and "small" presets, with 1 and 2 threads. Each benchmark also times a plain Eigen SGEMM
// of the network's dominant shape (mesh edges x L times L x L) in the same run and reports
//   gflops        achieved by the network (FLOPs counted by Network::forward_flops)
//   sgemm_gflops  achieved by the reference SGEMM just before
//   ratio         gflops / sgemm_gflops (aim: >= 0.5 for inference)
//
//   build/release/tests/bench/bench_network
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <chrono>

#include "fignet/graph/graph_builder.h"
#include "fignet/model/model.h"
#include "fignet/scenes/resting_lattice.h"
#include "fignet/train/training_batch.h"

namespace fignet {
namespace {

// GFLOP/s of an (rows x l) * (l x l) single-precision product, measured for ~0.2 s.
double sgemm_gflops(Eigen::Index rows, Eigen::Index l) {
  const RowMatrixXf a = RowMatrixXf::Random(rows, l), b = RowMatrixXf::Random(l, l);
  RowMatrixXf c(rows, l);
  int reps = 0;
  const auto start = std::chrono::steady_clock::now();
  double seconds = 0;
  do {
    c.noalias() = a * b;
    benchmark::DoNotOptimize(c.data());
    ++reps;
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } while (seconds < 0.2);
  return 2.0 * rows * l * l * reps / seconds / 1e9;
}

struct Setup {
  RestingLattice lattice;
  std::shared_ptr<Model> model;
  Graph graph;
};

Setup make_setup(const char* preset) {
  Setup s;
  RestingLatticeOptions options;
  options.objects = 6;
  options.seed = 1;
  options.scales = {0.7, 1.4};  // MOVi-A sizes
  s.lattice = make_resting_lattice(options);
  const ModelConfig config = ModelConfig::preset_named(preset);
  s.model = std::make_shared<Model>(config);
  GraphBuilder(config.graph).build(s.lattice.scene, s.graph);
  return s;
}

void report(benchmark::State& state, const Setup& s, double flops_per_iteration,
            double loop_seconds) {
  const double l = s.model->config().latent_size;
  state.counters["mesh_nodes"] = s.graph.num_mesh_nodes();
  state.counters["face_edges"] = s.graph.face_edges.size();
  state.counters["gflop"] = flops_per_iteration / 1e9;
  state.counters["gflops"] =
      benchmark::Counter(flops_per_iteration / 1e9, benchmark::Counter::kIsIterationInvariantRate);
  const double reference = sgemm_gflops(s.graph.mesh_edges.size(), static_cast<Eigen::Index>(l));
  state.counters["sgemm_gflops"] = reference;
  const double achieved = flops_per_iteration * state.iterations() / loop_seconds / 1e9;
  state.counters["ratio"] = achieved / reference;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BM_Inference(benchmark::State& state, const char* preset) {
  Eigen::setNbThreads(static_cast<int>(state.range(0)));
  Setup s = make_setup(preset);
  NetworkWorkspace workspace;
  const Network& network = s.model->network();
  network.forward(s.model->parameters().data(), s.model->normalizers(), s.graph, workspace, false);
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    benchmark::DoNotOptimize(network
                                 .forward(s.model->parameters().data(), s.model->normalizers(),
                                          s.graph, workspace, false)
                                 .data());
  }
  report(state, s, network.forward_flops(s.graph), seconds_since(start));
}

void BM_TrainingStep(benchmark::State& state, const char* preset) {
  Eigen::setNbThreads(static_cast<int>(state.range(0)));
  Setup s = make_setup(preset);
  NetworkWorkspace workspace;
  const Network& network = s.model->network();
  std::vector<float> grads(s.model->parameters().size());
  const RowMatrixXf d_output = RowMatrixXf::Ones(s.graph.num_mesh_nodes(), 3);
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    network.forward(s.model->parameters().data(), s.model->normalizers(), s.graph, workspace, true);
    std::fill(grads.begin(), grads.end(), 0.0f);
    network.backward(s.model->parameters().data(), grads.data(), s.graph, d_output, workspace);
    benchmark::DoNotOptimize(grads.data());
  }
  report(state, s, 3.0 * network.forward_flops(s.graph), seconds_since(start));  // bwd ≈ 2 fwd
}

BENCHMARK_CAPTURE(BM_Inference, paper, "paper")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Inference, small, "small")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainingStep, paper, "paper")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainingStep, small, "small")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace fignet

BENCHMARK_MAIN();
