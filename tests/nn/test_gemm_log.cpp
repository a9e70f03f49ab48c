// GemmLog records the products as they were asked for, from any thread; its FLOPs for a forward
// pass are the network's own count (Network::forward_flops, a formula over the graph's sizes),
// and a batch's products are the same whichever threads ran them.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <thread>
#include <tuple>

#include "../movi_lattices.h"
#include "../scoped_threads.h"
#include "fignet/error.h"
#include "fignet/graph/graph_builder.h"
#include "fignet/model/network_backend.h"
#include "fignet/nn/gemm_log.h"

namespace fignet {
namespace {

TEST(GemmLog, RecordsEachProductAsAsked) {
  const RowMatrixXf a = RowMatrixXf::Random(7, 5), b = RowMatrixXf::Random(5, 3);
  const RowMatrixXf bt = b.transpose();
  RowMatrixXf c(7, 3), w(5, 3), empty(0, 3);
  const std::vector<float> bias(3, 0.0f);
  GemmLog log;
  gemm(a, Transpose::kNo, bt, Transpose::kYes, c, false);
  gemm(a, Transpose::kYes, c, Transpose::kNo, w, true);
  gemm_bias(a, b, Transpose::kNo, bias.data(), Activation::kRelu, c);
  gemm(RowMatrixXf(0, 5), Transpose::kNo, b, Transpose::kNo, empty, false);  // no arithmetic
  const std::vector<GemmShape> expected = {
      {7, 5, 3, Transpose::kNo, Transpose::kYes, false, false, Activation::kNone},
      {5, 7, 3, Transpose::kYes, Transpose::kNo, true, false, Activation::kNone},
      {7, 5, 3, Transpose::kNo, Transpose::kNo, false, true, Activation::kRelu},
  };
  EXPECT_EQ(log.shapes(), expected);
  EXPECT_DOUBLE_EQ(log.flops(), 2.0 * (7 * 5 * 3 + 5 * 7 * 3 + 7 * 5 * 3));
  EXPECT_EQ(log.with_row_passes(), std::vector<bool>(3, false));
  const std::vector<double> seconds = log.seconds();
  ASSERT_EQ(seconds.size(), 3u);
  for (const double s : seconds) {
    EXPECT_GT(s, 0.0);
    EXPECT_LT(s, 1.0);
  }
}

// A product with a pass fused into its blocks is marked, and its time includes the pass's.
TEST(GemmLog, MarksProductsWithRowPasses) {
  const RowMatrixXf a = RowMatrixXf::Random(300, 8), b = RowMatrixXf::Random(8, 4);
  RowMatrixXf c(300, 4);
  const std::vector<float> bias(4, 0.0f);
  struct Slow {
    static void run(const void*, Eigen::Index, Eigen::Index) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  };
  GemmLog log;
  gemm_bias(a, b, Transpose::kNo, bias.data(), Activation::kNone, c, {}, {&Slow::run, nullptr});
  gemm_bias(a, b, Transpose::kNo, bias.data(), Activation::kNone, c);
  EXPECT_EQ(log.with_row_passes(), (std::vector<bool>{true, false}));
  EXPECT_GE(log.seconds()[0], 0.002);
}

TEST(GemmLog, OneAtATime) {
  {
    GemmLog first;
    EXPECT_THROW(GemmLog second, ConfigError);
  }
  GemmLog again;  // the first is gone
  const RowMatrixXf a = RowMatrixXf::Random(2, 2);
  RowMatrixXf c(2, 2);
  gemm(a, Transpose::kNo, a, Transpose::kNo, c, false);
  EXPECT_EQ(again.shapes().size(), 1u);
}

// A small-preset network (or `config`'s) on `count` MOVi-A-like scenes of 3, 4, ... objects,
// random parameters.
struct Scenes {
  Graph graph;
  Network network;
  std::vector<float> params;
  Normalizers normalizers;

  explicit Scenes(int count, const ModelConfig& config = ModelConfig::preset_named("small"))
      : network(config) {
    const std::vector<RestingLattice> lattices =
        testing::movi_a_lattices(count, [](int s) { return 3 + s; });
    GraphBuilder(network.config().graph).build(testing::scenes_of(lattices), graph);
    network.layout().initialize(params, 5);
    normalizers = network.make_normalizers();
    network.accumulate_input_statistics(graph, normalizers);
  }
};

TEST(GemmLog, ForwardFlopsAreTheNetworksCount) {
  const Scenes s(2);
  ASSERT_GT(s.graph.face_edges.size(), 0u);
  NetworkWorkspace workspace;
  GemmLog log;
  s.network.forward(s.params.data(), s.normalizers, s.graph, workspace, false);
  EXPECT_NEAR(log.flops(), s.network.forward_flops(s.graph), 1e-9 * log.flops());
}

// ... also with hidden layers wider than the latents, the object-node MLPs' wider still.
TEST(GemmLog, ForwardFlopsCountWiderHiddenLayers) {
  ModelConfig config = ModelConfig::preset_named("small");
  config.hidden_size = 96;
  config.object_hidden_size = 256;
  const Scenes s(2, config);
  NetworkWorkspace workspace;
  GemmLog log;
  s.network.forward(s.params.data(), s.normalizers, s.graph, workspace, false);
  EXPECT_NEAR(log.flops(), s.network.forward_flops(s.graph), 1e-9 * log.flops());
  EXPECT_GT(s.network.forward_flops(s.graph), Scenes(2).network.forward_flops(s.graph) * 1.5);
}

// The products of a batch's forward and backward, as a sorted list (threads start them in any
// order).
std::vector<GemmShape> batch_products(const Scenes& s, int threads) {
  const testing::ScopedEigenThreads scope(threads);
  auto backend = make_cpu_backend(s.network);
  std::vector<float> grads(s.params.size(), 0.0f);
  const LossGradient loss = [](int, const ConstMatrixRef& output, MatrixRef d_output) {
    d_output.setConstant(1.0f);
    return static_cast<double>(output.sum());
  };
  GemmLog log;
  backend->forward_backward(s.params.data(), s.normalizers, s.graph, grads.data(), loss);
  std::vector<GemmShape> shapes = log.shapes();
  auto key = [](const GemmShape& g) {
    return std::tuple(g.m, g.k, g.n, g.op_a, g.op_b, g.accumulate, g.bias, g.activation);
  };
  std::sort(shapes.begin(), shapes.end(),
            [&](const GemmShape& x, const GemmShape& y) { return key(x) < key(y); });
  return shapes;
}

TEST(GemmLog, RecordsEveryThreadsProducts) {
  const Scenes s(4);
  ASSERT_GT(s.graph.num_mesh_nodes(), 1000);  // more than one chunk (about 500 nodes each)
  const std::vector<GemmShape> one = batch_products(s, 1), two = batch_products(s, 2);
  EXPECT_EQ(one, two);
  // The backward pass does about twice the forward's arithmetic (a weight and an input gradient
  // per product; less where an input needs no gradient).
  double total = 0.0;
  for (const GemmShape& g : one) total += g.flops();
  const double forward = s.network.forward_flops(s.graph);
  EXPECT_GT(total, 2.0 * forward);
  EXPECT_LE(total, 3.0 * forward * (1 + 1e-9));
}

TEST(GemmLog, BareProductsTakeTime) {
  const std::vector<GemmShape> shapes = {
      {64, 32, 16, Transpose::kNo, Transpose::kNo, false, true, Activation::kRelu},
      {32, 64, 16, Transpose::kYes, Transpose::kNo, true, false, Activation::kNone},
      {64, 16, 32, Transpose::kNo, Transpose::kYes, false, false, Activation::kNone},
  };
  for (const int threads : {1, 2}) {
    const testing::ScopedEigenThreads scope(threads);
    for (const bool share_out : {false, true}) {
      std::vector<double> each;
      const double seconds = time_gemm_shapes(shapes, 0.01, share_out, &each);
      EXPECT_GT(seconds, 0.0);
      EXPECT_TRUE(std::isfinite(seconds));
      ASSERT_EQ(each.size(), shapes.size());
      for (const double s : each) EXPECT_GT(s, 0.0);
      // One at a time, the products' times lie inside the pass's.
      if (!share_out || threads == 1) {
        EXPECT_LE(std::accumulate(each.begin(), each.end(), 0.0), seconds);
      }
    }
  }
  EXPECT_EQ(time_gemm_shapes({}, 0.01, false), 0.0);
}

}  // namespace
}  // namespace fignet
