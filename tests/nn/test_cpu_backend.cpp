// The CPU backend runs a batch as chunks of whole scenes, in parallel: its outputs and gradients
// must be the whole graph's (to float rounding), and must not depend on the thread count. Also:
// the network through either product engine gives the same results to float tolerance.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "../movi_lattices.h"
#include "../scoped_threads.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/model/network_backend.h"
#include "fignet/nn/gemm.h"
#include "fignet/scenes/resting_lattice.h"

namespace fignet {
namespace {

// Eight MOVi-A-like scenes of six objects (~3,000 mesh nodes: several chunks), a small-preset
// network with random parameters, and normalisers from the batch.
struct Batch {
  std::vector<RestingLattice> lattices;
  Graph graph;
  Network network{ModelConfig::preset_named("small")};
  std::vector<float> params;
  Normalizers normalizers;
  RowMatrixXf weights;  // the loss is Σ weights·output

  explicit Batch(int scenes = 8) {
    lattices = testing::movi_a_lattices(scenes, [](int) { return 6; });
    GraphBuilder(network.config().graph).build(testing::scenes_of(lattices), graph);
    network.layout().initialize(params, 5);
    normalizers = network.make_normalizers();
    network.accumulate_input_statistics(graph, normalizers);
    std::mt19937 rng(3);
    std::normal_distribution<float> n;
    weights.resize(graph.num_mesh_nodes(), 3);
    for (Eigen::Index i = 0; i < weights.size(); ++i) weights.data()[i] = n(rng);
  }

  // Network::forward and backward over the whole graph in one piece: output and gradients.
  std::pair<RowMatrixXf, std::vector<float>> run_whole() const {
    NetworkWorkspace workspace;
    RowMatrixXf output = network.forward(params.data(), normalizers, graph, workspace, true);
    std::vector<float> grads(params.size(), 0.0f);
    network.backward(params.data(), grads.data(), graph, weights, workspace);
    return {output, grads};
  }

  LossGradient loss() const {
    return [this](int first, const ConstMatrixRef& output, MatrixRef d_output) {
      d_output = weights.middleRows(first, output.rows());
      return static_cast<double>(
          (output.array() * weights.middleRows(first, output.rows()).array()).sum());
    };
  }
};

// Runs f with Eigen::nbThreads() == threads.
template <class F>
auto with_threads(int threads, F&& f) {
  const testing::ScopedEigenThreads scope(threads);
  return f();
}

double max_abs(const std::vector<float>& a) {
  double m = 0.0;
  for (float x : a) m = std::max(m, static_cast<double>(std::abs(x)));
  return m;
}

double max_difference(const std::vector<float>& a, const std::vector<float>& b) {
  double m = 0.0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, static_cast<double>(std::abs(a[i] - b[i])));
  return m;
}

TEST(CpuBackend, ChunkedOutputsAndGradientsEqualTheWholeGraphs) {
  const Batch batch;
  ASSERT_GT(batch.graph.num_mesh_nodes(), 2500);
  const auto [whole_output, whole_grads] = batch.run_whole();
  // The backend, in chunks.
  auto backend = make_cpu_backend(batch.network);
  const RowMatrixXf output =
      backend->forward(batch.params.data(), batch.normalizers, batch.graph, false);
  EXPECT_LT((output - whole_output).cwiseAbs().maxCoeff(), 1e-4);
  std::vector<float> grads(batch.params.size(), 0.0f);
  const double loss = backend->forward_backward(batch.params.data(), batch.normalizers, batch.graph,
                                                grads.data(), batch.loss());
  const double whole_loss = (whole_output.array() * batch.weights.array()).sum();
  EXPECT_NEAR(loss, whole_loss, 1e-4 * std::abs(whole_loss) + 1e-3);
  EXPECT_LT(max_difference(grads, whole_grads), 1e-4 * max_abs(whole_grads));
}

TEST(CpuBackend, ResultsDoNotDependOnTheThreadCount) {
  const Batch batch;
  struct Result {
    RowMatrixXf output;
    std::vector<float> grads, split_grads;
    double loss = 0.0;
  };
  auto run = [&](int threads) {
    return with_threads(threads, [&] {
      auto backend = make_cpu_backend(batch.network);
      Result r;
      r.output = backend->forward(batch.params.data(), batch.normalizers, batch.graph, false);
      r.grads.assign(batch.params.size(), 0.0f);
      r.loss = backend->forward_backward(batch.params.data(), batch.normalizers, batch.graph,
                                         r.grads.data(), batch.loss());
      // forward(keep) then backward: the same chunks, the same sums.
      backend->forward(batch.params.data(), batch.normalizers, batch.graph, true);
      r.split_grads.assign(batch.params.size(), 0.0f);
      backend->backward(batch.params.data(), r.split_grads.data(), batch.graph, batch.weights);
      return r;
    });
  };
  const Result one = run(1), two = run(2), four = run(4);
  for (const Result* other : {&two, &four}) {
    EXPECT_EQ(other->output, one.output);
    EXPECT_EQ(other->grads, one.grads);
    EXPECT_EQ(other->loss, one.loss);
  }
  EXPECT_EQ(one.split_grads, one.grads);
}

// A batch of over 16 chunks' worth (~9,000 mesh nodes) runs in 16 larger chunks, each with its
// gradient buffer: still the whole graph's results, and the same for any thread count.
TEST(CpuBackend, LargeBatchesToo) {
  const Batch batch(24);
  ASSERT_GT(batch.graph.num_mesh_nodes(), 16 * 500);
  const auto [whole_output, whole_grads] = batch.run_whole();
  auto run = [&](int threads) {
    return with_threads(threads, [&] {
      auto backend = make_cpu_backend(batch.network);
      std::vector<float> grads(batch.params.size(), 0.0f);
      backend->forward_backward(batch.params.data(), batch.normalizers, batch.graph, grads.data(),
                                batch.loss());
      return grads;
    });
  };
  const std::vector<float> one = run(1);
  // Sums over three times the rows of the batch above round further apart (1.1e-4 of the largest
  // gradient on oneDNN's avx2 kernels); a scene left out or counted twice moves them by percents.
  EXPECT_LT(max_difference(one, whole_grads), 1e-3 * max_abs(whole_grads));
  EXPECT_EQ(run(2), one);
}

// The chunks' gradient buffers are reused from call to call (zeroed as they are summed): a second
// call gives the first's bits, and so does a call after one whose loss threw midway through the
// chunks (its buffers left half filled).
TEST(CpuBackend, RepeatedCallsAndACallAfterAFailureGiveTheSameBits) {
  const Batch batch;
  auto backend = make_cpu_backend(batch.network);
  auto step = [&](const LossGradient& loss) {
    std::vector<float> grads(batch.params.size(), 0.0f);
    backend->forward_backward(batch.params.data(), batch.normalizers, batch.graph, grads.data(),
                              loss);
    return grads;
  };
  const std::vector<float> first = step(batch.loss());
  EXPECT_EQ(step(batch.loss()), first);
  for (int threads : {1, 2}) {
    with_threads(threads, [&] {
      std::atomic<int> calls = 0;  // the chunks' threads call the loss
      const LossGradient fails_on_the_third = [&](int first_node, const ConstMatrixRef& output,
                                                  MatrixRef d_output) {
        if (++calls == 3) throw std::runtime_error("loss failed");
        return batch.loss()(first_node, output, d_output);
      };
      EXPECT_THROW(step(fails_on_the_third), std::runtime_error);
      EXPECT_GE(calls, 3);
      EXPECT_EQ(step(batch.loss()), first) << threads << " thread(s)";
      return 0;
    });
  }
}

// One graph run whole (a single scene, a small batch) threads its products instead: the same
// bits for any thread count too.
TEST(CpuBackend, WholeGraphResultsDoNotDependOnTheThreadCount) {
  const Batch batch;
  auto run = [&](int threads) { return with_threads(threads, [&] { return batch.run_whole(); }); };
  const auto one = run(1), two = run(2), four = run(4);
  EXPECT_EQ(two.first, one.first);
  EXPECT_EQ(four.first, one.first);
  EXPECT_EQ(two.second, one.second);
  EXPECT_EQ(four.second, one.second);
}

// The network's products through Eigen and through oneDNN agree to float tolerance.
TEST(CpuBackend, ProductEnginesAgree) {
  if (!gemm_engine_available(GemmEngine::kOneDnn)) GTEST_SKIP() << "this build has no oneDNN";
  const Batch batch;
  const GemmEngine previous = gemm_engine();
  auto run = [&](GemmEngine engine) {
    set_gemm_engine(engine);
    return batch.run_whole();
  };
  const auto eigen = run(GemmEngine::kEigen), onednn = run(GemmEngine::kOneDnn);
  set_gemm_engine(previous);
  EXPECT_LT((eigen.first - onednn.first).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT(max_difference(eigen.second, onednn.second), 1e-4 * max_abs(eigen.second));
}

// bf16 products (`fignet train --bf16`) through the whole network, against f32 products. How far
// they may differ is measured, not guessed: at random initialisation the network's outputs and
// gradients are sensitive enough that perturbing every f32 parameter by a random relative 2^-9
// (the size of bf16 rounding) moves the gradient by ~12 % (relative L2, random-signed loss
// weights: sums over thousands of rows cancel, so ReLUs that flip weigh in). bf16 rounds the
// activations too: its gradient must stay within twice that perturbation's effect and its outputs
// within three times (measured on the Zen 5 VM: 1.3x and 1.8x), differ from f32 at all, and give
// the same bits for any thread count.
TEST(CpuBackend, Bf16ProductsStayNearF32AndRepeatForAnyThreadCount) {
  const std::string why_not = gemm_precision_unavailable(GemmPrecision::kBf16);
  if (!why_not.empty()) GTEST_SKIP() << why_not;
  Batch batch;
  auto run = [&](GemmPrecision precision, int threads) {
    set_gemm_precision(precision);
    auto result = with_threads(threads, [&] {
      auto backend = make_cpu_backend(batch.network);
      const RowMatrixXf output =
          backend->forward(batch.params.data(), batch.normalizers, batch.graph, false);
      std::vector<float> grads(batch.params.size(), 0.0f);
      backend->forward_backward(batch.params.data(), batch.normalizers, batch.graph, grads.data(),
                                batch.loss());
      return std::pair{output, grads};
    });
    set_gemm_precision(GemmPrecision::kF32);
    return result;
  };
  auto relative_l2 = [](const std::vector<float>& a, const std::vector<float>& b) {
    double difference = 0.0, norm = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
      difference += std::pow(static_cast<double>(a[i]) - b[i], 2);
      norm += std::pow(static_cast<double>(b[i]), 2);
    }
    return std::sqrt(difference / norm);
  };
  const auto f32 = run(GemmPrecision::kF32, 1);
  // The reference: f32 products, parameters perturbed.
  const std::vector<float> params = batch.params;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (float& x : batch.params) x *= 1.0f + u(rng) * 0x1p-9f;
  const auto perturbed = run(GemmPrecision::kF32, 1);
  batch.params = params;
  const auto bf16 = run(GemmPrecision::kBf16, 1), bf16_two = run(GemmPrecision::kBf16, 2);

  const double perturbed_output = (perturbed.first - f32.first).cwiseAbs().maxCoeff();
  const double bf16_output = (bf16.first - f32.first).cwiseAbs().maxCoeff();
  EXPECT_GT(bf16_output, 0.0);
  EXPECT_LT(bf16_output, 3.0 * perturbed_output);
  EXPECT_LT(relative_l2(bf16.second, f32.second), 2.0 * relative_l2(perturbed.second, f32.second));
  EXPECT_EQ(bf16_two.first, bf16.first);
  EXPECT_EQ(bf16_two.second, bf16.second);
}

}  // namespace
}  // namespace fignet
