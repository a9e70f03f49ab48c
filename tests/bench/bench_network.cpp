// FIGNet inference and training on MOVi-A-like scenes (~380 mesh nodes each), for the "paper"
// and "small" presets, with 1 and 2 threads. Every figure is set against references measured in
// the same run:
//   gflops         achieved by the network (FLOPs counted by Network::forward_flops; a
//                  training step counts 3x the forward)
//   sgemm_gflops   gemm() with the build's engine (oneDNN: its matmul primitive for full blocks
//                  of rows, sgemm for the rest; Eigen without oneDNN) on the network's dominant
//                  shape, mesh edges x L times L x L, with the same threads; ratio = gflops / that
//   eigen_gflops   Eigen's SGEMM on the same shape (the products' engine before oneDNN)
//   peak_gflops    the processor's fp32 peak: independent FMA chains on the widest vectors it
//                  has (AVX-512 or AVX2, chosen at run time) on every thread; of_peak = gflops /
//                  peak
//   bare_ms        the very products one iteration ran (recorded by GemmLog: shapes, layouts,
//                  bias and ReLU), run bare on the same threads, as a batch's are when chunked;
//                  of_bare = bare_ms / the iteration's ms: the share of the time that is products
//                  at the speed they have alone. product_gflop: their exact FLOPs per iteration
//                  (gflop is the count above: 3x the forward for training)
//   in_step_ms     the same products timed where they ran, inside the iteration (mean of 8
//                  calls; shared out, summed over the threads and divided by their number);
//                  of_in_step = in_step_ms / the iteration's ms. weight_grad_slowdown and
//                  other_slowdown: the weight gradients' (aᵀ·b) and the other products' time in
//                  the iteration over their time bare, leaving out products whose blocks carry
//                  fused row passes (LayerNorm), which bare runs without. Above 1: operands the
//                  step left out of cache (the forward's activations, read again by the backward)
// FIGNET_PRODUCTS_CSV=file appends every product's shape and its in-step and bare microseconds.
// BM_TrainingBatch trains on a batch of 16 scenes as `fignet train` does and reports samples/s:
// "whole_eigen" is the path before the CPU backend work (the batch as one graph, Eigen products
// threaded one by one), "chunked" the CPU backend (chunks of scenes in parallel, the build's
// product engine), "chunked_bf16" the same with bf16 products (`fignet train --bf16`; skipped
// where the processor has no bf16 instructions), with one more reference:
//   bf16_gemm_gflops  gemm() in bf16 on the dominant shape, same threads
// (sgemm_gflops and ratio stay f32 ones: how far bf16 takes the step past f32's ceiling).
//
//   build/release/tests/bench/bench_network
#include <benchmark/benchmark.h>
#include <immintrin.h>
#include <omp.h>

#include <Eigen/Core>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "../movi_lattices.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/model/model.h"
#include "fignet/model/network_backend.h"
#include "fignet/nn/gemm.h"
#include "fignet/nn/gemm_log.h"
#include "fignet/scenes/resting_lattice.h"
#include "fignet/train/training_batch.h"

namespace fignet {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// GFLOP/s of f, which does `flops` per call, measured for ~0.2 s.
template <class F>
double gflops_of(F&& f, double flops) {
  int reps = 0;
  const auto start = std::chrono::steady_clock::now();
  double seconds = 0;
  do {
    f();
    ++reps;
    seconds = seconds_since(start);
  } while (seconds < 0.2);
  return flops * reps / seconds / 1e9;
}

// GFLOP/s of an (rows x l) * (l x l) product through gemm() with the given engine.
double sgemm_gflops(Eigen::Index rows, Eigen::Index l, GemmEngine engine) {
  const GemmEngine previous = gemm_engine();
  set_gemm_engine(engine);
  const RowMatrixXf a = RowMatrixXf::Random(rows, l), b = RowMatrixXf::Random(l, l);
  RowMatrixXf c(rows, l);
  const double rate = gflops_of(
      [&] {
        gemm(a, Transpose::kNo, b, Transpose::kNo, c, false);
        benchmark::DoNotOptimize(c.data());
      },
      2.0 * rows * l * l);
  set_gemm_engine(previous);
  return rate;
}

// Independent FMA chains (more than latency x units) on 8 or 16 floats: the core's fp32 peak.
constexpr int kChains = 12;
constexpr long kFmaIterations = 20'000'000;

__attribute__((target("avx2,fma"))) double fma_seconds_avx2() {
  __m256 acc[kChains];
  for (int j = 0; j < kChains; ++j) acc[j] = _mm256_set1_ps(static_cast<float>(j));
  const __m256 a = _mm256_set1_ps(0.999999f), b = _mm256_set1_ps(1e-7f);
  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < kFmaIterations; ++i) {
    for (int j = 0; j < kChains; ++j) acc[j] = _mm256_fmadd_ps(acc[j], a, b);
  }
  const double seconds = seconds_since(start);
  for (int j = 1; j < kChains; ++j) acc[0] = _mm256_add_ps(acc[0], acc[j]);
  benchmark::DoNotOptimize(acc[0]);
  return seconds;
}

__attribute__((target("avx512f"))) double fma_seconds_avx512() {
  __m512 acc[kChains];
  for (int j = 0; j < kChains; ++j) acc[j] = _mm512_set1_ps(static_cast<float>(j));
  const __m512 a = _mm512_set1_ps(0.999999f), b = _mm512_set1_ps(1e-7f);
  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < kFmaIterations; ++i) {
    for (int j = 0; j < kChains; ++j) acc[j] = _mm512_fmadd_ps(acc[j], a, b);
  }
  const double seconds = seconds_since(start);
  for (int j = 1; j < kChains; ++j) acc[0] = _mm512_add_ps(acc[0], acc[j]);
  benchmark::DoNotOptimize(acc[0]);
  return seconds;
}

// The fp32 peak of `threads` cores in GFLOP/s: the better of AVX2 and AVX-512 where present
// (some processors run AVX-512 at half width, so wider is not always faster).
double peak_gflops(int threads) {
  auto rate = [&](double (*kernel)(), int lanes) {
    double total = 0.0;
#pragma omp parallel num_threads(threads) reduction(+ : total)
    total += 2.0 * lanes * kChains * kFmaIterations / kernel() / 1e9;
    return total;
  };
  double peak = 0.0;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    peak = rate(fma_seconds_avx2, 8);
  }
  if (__builtin_cpu_supports("avx512f")) peak = std::max(peak, rate(fma_seconds_avx512, 16));
  return peak;
}

struct Setup {
  RestingLattice lattice;
  std::shared_ptr<Model> model;
  Graph graph;
};

Setup make_setup(const char* preset) {
  Setup s;
  std::vector<RestingLattice> one = testing::movi_a_lattices(1, [](int) { return 6; });
  s.lattice = std::move(one.front());  // a lattice owns its meshes: moved, not copied
  const ModelConfig config = ModelConfig::preset_named(preset);
  s.model = std::make_shared<Model>(config);
  GraphBuilder(config.graph).build(s.lattice.scene, s.graph);
  return s;
}

// The same-run references of a figure of `achieved` GFLOP/s on `threads` threads.
void add_references(benchmark::State& state, double achieved, Eigen::Index mesh_edges,
                    Eigen::Index latent_size, int threads) {
  const double sgemm = sgemm_gflops(mesh_edges, latent_size, gemm_engine());
  const double peak = peak_gflops(threads);
  state.counters["gflops"] = achieved;
  state.counters["sgemm_gflops"] = sgemm;
  state.counters["eigen_gflops"] = sgemm_gflops(mesh_edges, latent_size, GemmEngine::kEigen);
  state.counters["peak_gflops"] = peak;
  state.counters["ratio"] = achieved / sgemm;
  state.counters["of_peak"] = achieved / peak;
}

// Appends one line per product of an iteration to the CSV file at `path`: its shape, layouts and
// its mean microseconds inside the iteration (`in_step` holds several calls' products in turn)
// and bare.
void write_products_csv(const char* path, const std::string& benchmark,
                        const std::vector<GemmShape>& shapes, const std::vector<double>& in_step,
                        const std::vector<bool>& row_passes, const std::vector<double>& bare) {
  if (shapes.empty()) return;
  std::FILE* file = std::fopen(path, "a");
  if (file == nullptr) {
    std::fprintf(stderr, "FIGNET_PRODUCTS_CSV: cannot open %s for appending\n", path);
    return;
  }
  const size_t count = shapes.size(), calls = in_step.size() / count;
  if (std::ftell(file) == 0) {
    std::fprintf(file,
                 "benchmark,index,m,k,n,a_transposed,b_transposed,accumulate,bias,"
                 "row_passes,in_step_us,bare_us\n");
  }
  for (size_t j = 0; j < count; ++j) {
    double seconds = 0.0;
    for (size_t call = 0; call < calls; ++call) seconds += in_step[call * count + j] / calls;
    const GemmShape& g = shapes[j];
    std::fprintf(file, "%s,%zu,%ld,%ld,%ld,%d,%d,%d,%d,%d,%.3f,%.3f\n", benchmark.c_str(), j,
                 static_cast<long>(g.m), static_cast<long>(g.k), static_cast<long>(g.n),
                 g.op_a == Transpose::kYes, g.op_b == Transpose::kYes, g.accumulate, g.bias,
                 static_cast<bool>(row_passes[j]), 1e6 * seconds, 1e6 * bare[j]);
  }
  std::fclose(file);
}

// The products of one call of `iteration`, run bare: their exact FLOPs and what share of an
// iteration's `seconds` they take alone; and the same products timed inside the iteration (over a
// few calls), set against their bare times: how much slower they run among the passes.
template <class F>
void add_bare_products(benchmark::State& state, const std::string& label, F&& iteration,
                       double seconds, bool share_out) {
  constexpr int kLoggedCalls = 8;
  std::vector<GemmShape> logged;
  std::vector<double> in_step;
  std::vector<bool> row_passes;
  {
    const GemmLog log;
    for (int i = 0; i < kLoggedCalls; ++i) iteration();
    logged = log.shapes();
    in_step = log.seconds();
    row_passes = log.with_row_passes();
  }
  const size_t count = logged.size() / kLoggedCalls;
  const std::vector<GemmShape> shapes(logged.begin(), logged.begin() + count);
  double flops = 0.0;
  for (const GemmShape& g : shapes) flops += g.flops();
  std::vector<double> bare_each;
  const double bare = time_gemm_shapes(shapes, 0.2, share_out, &bare_each);
  // Sums per iteration over the products, split into weight gradients (aᵀ·b) and the rest; the
  // products with passes fused into their blocks are left out of the in-step comparison. Shared
  // out, a call's products start in any order, so the sums go by kind, not by position.
  double step_weight = 0.0, bare_weight = 0.0, step_rest = 0.0, bare_rest = 0.0, step_all = 0.0;
  for (size_t i = 0; i < logged.size(); ++i) {
    step_all += in_step[i] / kLoggedCalls;
    if (row_passes[i]) continue;
    (logged[i].op_a == Transpose::kYes ? step_weight : step_rest) += in_step[i] / kLoggedCalls;
  }
  for (size_t j = 0; j < count; ++j) {
    if (row_passes[j]) continue;
    (shapes[j].op_a == Transpose::kYes ? bare_weight : bare_rest) += bare_each[j];
  }
  if (const char* path = std::getenv("FIGNET_PRODUCTS_CSV")) {
    // One thread runs every call's products in the same order; shared out, only the first
    // call's times line up with `shapes`.
    const size_t calls = share_out ? 1 : kLoggedCalls;
    write_products_csv(path, label, shapes,
                       std::vector<double>(in_step.begin(), in_step.begin() + calls * count),
                       row_passes, bare_each);
  }
  const double threads = share_out ? Eigen::nbThreads() : 1;
  state.counters["product_gflop"] = flops / 1e9;
  state.counters["bare_ms"] = 1e3 * bare;
  state.counters["of_bare"] = bare / seconds;
  state.counters["in_step_ms"] = 1e3 * step_all / threads;
  state.counters["of_in_step"] = step_all / threads / seconds;
  state.counters["weight_grad_slowdown"] = bare_weight > 0.0 ? step_weight / bare_weight : 0.0;
  state.counters["other_slowdown"] = bare_rest > 0.0 ? step_rest / bare_rest : 0.0;
}

void report(benchmark::State& state, const Setup& s, double flops_per_iteration,
            double loop_seconds, int threads) {
  state.counters["mesh_nodes"] = s.graph.num_mesh_nodes();
  state.counters["face_edges"] = s.graph.face_edges.size();
  state.counters["gflop"] = flops_per_iteration / 1e9;
  const double achieved = flops_per_iteration * state.iterations() / loop_seconds / 1e9;
  add_references(state, achieved, s.graph.mesh_edges.size(), s.model->config().latent_size,
                 threads);
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
  const double seconds = seconds_since(start);
  report(state, s, network.forward_flops(s.graph), seconds, static_cast<int>(state.range(0)));
  add_bare_products(
      state, std::string("Inference/") + preset + "/" + std::to_string(state.range(0)),
      [&] {
        network.forward(s.model->parameters().data(), s.model->normalizers(), s.graph, workspace,
                        false);
      },
      seconds / state.iterations(), false);
  Eigen::setNbThreads(0);
}

void BM_TrainingStep(benchmark::State& state, const char* preset) {
  Eigen::setNbThreads(static_cast<int>(state.range(0)));
  Setup s = make_setup(preset);
  NetworkWorkspace workspace;
  const Network& network = s.model->network();
  std::vector<float> grads(s.model->parameters().size());
  const RowMatrixXf d_output = RowMatrixXf::Ones(s.graph.num_mesh_nodes(), 3);
  auto step = [&] {
    network.forward(s.model->parameters().data(), s.model->normalizers(), s.graph, workspace, true);
    std::fill(grads.begin(), grads.end(), 0.0f);
    network.backward(s.model->parameters().data(), grads.data(), s.graph, d_output, workspace);
    benchmark::DoNotOptimize(grads.data());
  };
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) step();
  const double seconds = seconds_since(start);
  report(state, s, 3.0 * network.forward_flops(s.graph), seconds,  // bwd ≈ 2 fwd
         static_cast<int>(state.range(0)));
  add_bare_products(state,
                    std::string("TrainingStep/") + preset + "/" + std::to_string(state.range(0)),
                    step, seconds / state.iterations(), false);
  Eigen::setNbThreads(0);
}

// A training batch of 16 scenes (different lattices), forward and backward, as `fignet train`
// runs it: the batch as one graph with Eigen's products threaded one by one (before), or the CPU
// backend's chunks in parallel with the build's engine (now).
enum class BatchPath { kWholeEigen, kChunked, kChunkedBf16 };

void BM_TrainingBatch(benchmark::State& state, const char* preset, BatchPath path) {
  const int threads = static_cast<int>(state.range(0));
  const bool chunked = path != BatchPath::kWholeEigen, bf16 = path == BatchPath::kChunkedBf16;
  if (bf16) {
    const std::string why_not = gemm_precision_unavailable(GemmPrecision::kBf16);
    if (!why_not.empty()) {
      state.SkipWithError(("bf16 products: " + why_not).c_str());
      return;
    }
  }
  constexpr int kScenes = 16;
  // MOVi-A: 3 to 10 objects.
  const std::vector<RestingLattice> lattices =
      testing::movi_a_lattices(kScenes, [](int s) { return 3 + s % 8; });
  const std::vector<Scene> scenes = testing::scenes_of(lattices);
  const Model model(ModelConfig::preset_named(preset));
  const Network& network = model.network();
  Graph graph;
  GraphBuilder(model.config().graph).build(scenes, graph);
  const RowMatrixXf d_output = RowMatrixXf::Ones(graph.num_mesh_nodes(), 3);
  std::vector<float> grads(model.parameters().size());
  const float* params = model.parameters().data();
  const GemmEngine engine = gemm_engine();
  if (!chunked) set_gemm_engine(GemmEngine::kEigen);
  Eigen::setNbThreads(threads);
  NetworkWorkspace workspace;
  auto backend = make_cpu_backend(network);
  const LossGradient loss = [&](int first, const ConstMatrixRef& output, MatrixRef d) {
    d = d_output.middleRows(first, output.rows());
    return 0.0;
  };
  auto step = [&] {
    std::fill(grads.begin(), grads.end(), 0.0f);
    if (chunked) {
      backend->forward_backward(params, model.normalizers(), graph, grads.data(), loss);
    } else {
      network.forward(params, model.normalizers(), graph, workspace, true);
      network.backward(params, grads.data(), graph, d_output, workspace);
    }
    benchmark::DoNotOptimize(grads.data());
  };
  if (bf16) set_gemm_precision(GemmPrecision::kBf16);
  step();  // buffers grow once
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) step();
  const double seconds = seconds_since(start);
  if (bf16) {
    state.counters["bf16_gemm_gflops"] =
        sgemm_gflops(graph.mesh_edges.size() / kScenes, model.config().latent_size, engine);
    set_gemm_precision(GemmPrecision::kF32);
  }
  state.counters["mesh_nodes"] = graph.num_mesh_nodes();
  state.counters["samples_per_second"] = kScenes * state.iterations() / seconds;
  // The products' engine of this run for the references: Eigen for the path before.
  const double achieved = 3.0 * network.forward_flops(graph) * state.iterations() / seconds / 1e9;
  add_references(state, achieved, graph.mesh_edges.size() / kScenes, model.config().latent_size,
                 threads);
  if (bf16) set_gemm_precision(GemmPrecision::kBf16);
  add_bare_products(state,
                    std::string("TrainingBatch/") + preset +
                        (!chunked ? "_whole_eigen/"
                         : bf16   ? "_chunked_bf16/"
                                  : "_chunked/") +
                        std::to_string(threads),
                    step, seconds / state.iterations(), chunked);
  if (bf16) set_gemm_precision(GemmPrecision::kF32);
  Eigen::setNbThreads(0);
  set_gemm_engine(engine);
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
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainingBatch, small_whole_eigen, "small", BatchPath::kWholeEigen)
    ->Arg(1)
    ->Arg(2)
    ->MinTime(3.0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainingBatch, small_chunked, "small", BatchPath::kChunked)
    ->Arg(1)
    ->Arg(2)
    ->MinTime(3.0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_TrainingBatch, small_chunked_bf16, "small", BatchPath::kChunkedBf16)
    ->Arg(1)
    ->Arg(2)
    ->MinTime(3.0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace fignet

BENCHMARK_MAIN();
