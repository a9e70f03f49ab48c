#include <gtest/gtest.h>

#include <random>

#include "../scoped_threads.h"
#include "fignet/nn/adam.h"
#include "fignet/nn/mlp.h"
#include "fignet/nn/ops.h"
#include "gradient_check.h"

namespace fignet {
namespace {

RowMatrixXf random_matrix(std::mt19937& rng, int rows, int cols) {
  std::normal_distribution<float> n;
  RowMatrixXf m(rows, cols);
  for (int i = 0; i < m.size(); ++i) m.data()[i] = n(rng);
  return m;
}

std::vector<std::int32_t> random_index(std::mt19937& rng, int count, int range) {
  std::uniform_int_distribution<int> u(0, range - 1);
  std::vector<std::int32_t> index(count);
  for (auto& i : index) i = u(rng);
  return index;
}

TEST(Ops, ScatterAddIsTheAdjointOfGatherAdd) {
  std::mt19937 rng(1);
  const RowMatrixXf nodes = random_matrix(rng, 7, 5), edges = random_matrix(rng, 20, 5);
  const auto index = random_index(rng, 20, 7);
  const IndexSpan span{index.data(), 20};
  RowMatrixXf gathered = RowMatrixXf::Zero(20, 5), scattered = RowMatrixXf::Zero(7, 5);
  gather_add(nodes, span, gathered);
  scatter_add(edges, span, scattered);
  // <gather(x), y> = <x, scatter(y)>
  EXPECT_NEAR(gathered.cwiseProduct(edges).sum(), nodes.cwiseProduct(scattered).sum(), 1e-4);
  // Strided spans read every third entry.
  const IndexSpan second{index.data(), 6, 3, 1};
  EXPECT_EQ(second[2], index[7]);
}

// Both ways of forming a gathered product (per node then gathered, where the edges outnumber the
// nodes; gathered then per edge, where they do not) against the explicit gather-then-multiply,
// on a nonzero z and dx that they must add to, and through a strided span as face edges use.
class GatheredProduct : public ::testing::TestWithParam<int> {};

TEST_P(GatheredProduct, EqualsGatherThenMultiply) {
  const int edges = GetParam(), nodes = 9;
  std::mt19937 rng(2 + edges);
  const RowMatrixXf x = random_matrix(rng, nodes, 4), w = random_matrix(rng, 4, 6);
  const auto index = random_index(rng, 3 * edges, nodes);
  const IndexSpan span{index.data(), edges, 3, 2};  // every third entry from the third
  const RowMatrixXf z0 = random_matrix(rng, edges, 6);
  RowMatrixXf z = z0, gathered = RowMatrixXf::Zero(edges, 4);
  Buffer scratch;
  add_gathered_product(x, w, span, z, scratch);
  gather_add(x, span, gathered);
  EXPECT_TRUE(z.isApprox(z0 + gathered * w, 1e-5f));
  // Its adjoint against the explicit form: dx += scatter(dz·wᵀ), dw += gatheredᵀ·dz.
  const RowMatrixXf dz = random_matrix(rng, edges, 6);
  const RowMatrixXf dw0 = random_matrix(rng, 4, 6), dx0 = random_matrix(rng, nodes, 4);
  RowMatrixXf dw = dw0, dx = dx0;
  MatrixRef dx_ref = dx;
  backprop_gathered_product(x, w, span, dz, dw, &dx_ref, scratch);
  RowMatrixXf expected_dx = dx0;
  scatter_add(dz * w.transpose(), span, expected_dx);
  EXPECT_TRUE(dw.isApprox(dw0 + gathered.transpose() * dz, 1e-4f));
  EXPECT_TRUE(dx.isApprox(expected_dx, 1e-4f));
  // Without dx only the weight gradient accumulates.
  RowMatrixXf dw_only = dw0;
  backprop_gathered_product(x, w, span, dz, dw_only, nullptr, scratch);
  EXPECT_TRUE(dw_only.isApprox(dw, 1e-5f));
}

// 30 edges over 9 nodes (multiplied per node), 9 (the boundary), 4 (gathered first), 1.
INSTANTIATE_TEST_SUITE_P(Ops, GatheredProduct, ::testing::Values(30, 9, 4, 1));

class MlpGradient : public ::testing::TestWithParam<bool> {};

TEST_P(MlpGradient, MatchesFiniteDifferences) {
  const bool layer_norm = GetParam();
  ParameterLayout layout;
  const Mlp mlp(layout, "mlp", {3, 4}, 6, 5, layer_norm);
  std::vector<float> params;
  layout.initialize(params, 3);
  std::mt19937 rng(4);
  const RowMatrixXf a = random_matrix(rng, 8, 3), b = random_matrix(rng, 8, 4);
  const RowMatrixXf weights = random_matrix(rng, 8, 5);  // loss = Σ out ⊙ weights
  Buffer first;
  MlpCache cache;
  RowMatrixXf out(8, 5);
  auto run = [&](const std::vector<float>& p) {
    MatrixView z = first.view(8, 6);
    z.noalias() = a * mlp.first_weight(p.data(), 0);
    z.noalias() += b * mlp.first_weight(p.data(), 1);
    mlp.forward(p.data(), z, cache, out);
    return out.cast<double>().cwiseProduct(weights.cast<double>()).sum();
  };
  run(params);
  std::vector<float> grads(layout.size(), 0.0f);
  mlp.backward(params.data(), grads.data(), weights, cache);
  MatrixView dw_a = mlp.first_weight(grads.data(), 0), dw_b = mlp.first_weight(grads.data(), 1);
  dw_a.noalias() += a.transpose() * cache.d_first.get();
  dw_b.noalias() += b.transpose() * cache.d_first.get();
  EXPECT_EQ(testing::check_gradients(layout, params, grads, run, 40), 0);
}

INSTANTIATE_TEST_SUITE_P(WithAndWithoutLayerNorm, MlpGradient, ::testing::Bool());

TEST(Mlp, LayerNormOutputHasZeroMeanUnitVariancePerRow) {
  ParameterLayout layout;
  const Mlp mlp(layout, "mlp", {4}, 16, 32, true);
  std::vector<float> params;
  layout.initialize(params, 5);
  std::mt19937 rng(6);
  const RowMatrixXf x = random_matrix(rng, 10, 4);
  Buffer first;
  MlpCache cache;
  RowMatrixXf out(10, 32);
  mlp.forward_dense(params.data(), x, first, cache, out);
  for (int r = 0; r < 10; ++r) {
    EXPECT_NEAR(out.row(r).mean(), 0.0f, 1e-5f);
    EXPECT_NEAR((out.row(r).array() - out.row(r).mean()).square().mean(), 1.0f, 5e-3f);  // ε = 1e-5
  }
}

// The forward pass over rows of several product blocks (the full ones run through oneDNN's
// primitive, the last partial one through sgemm; the first layer's ReLU and LayerNorm run on each
// block as the products reach it), into a matrix of its own and into a column block of a wider
// one: against the MLP in double precision from its parameters, the neighbouring columns
// untouched, and the same bits for any thread count.
TEST(Mlp, ForwardOverManyBlocksMatchesADoublePrecisionMlpForAnyThreadCount) {
  using MatrixXdRow = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  constexpr int kRows = 700, kInput = 12, kHidden = 64, kOutput = 64;
  ParameterLayout layout;
  const Mlp mlp(layout, "mlp", {kInput}, kHidden, kOutput, true);
  std::vector<float> params;
  layout.initialize(params, 7);
  std::mt19937 rng(8);
  std::normal_distribution<float> perturbation(0.0f, 0.3f);
  for (float& p : params) p += perturbation(rng);  // biases, scale and offset away from 0 and 1
  const RowMatrixXf x = random_matrix(rng, kRows, kInput);

  const MlpTensors t = mlp.tensors();
  auto tensor_d = [&](size_t offset, int rows, int cols) {
    return MatrixXdRow(
        Eigen::Map<const RowMatrixXf>(params.data() + offset, rows, cols).cast<double>());
  };
  MatrixXdRow h = x.cast<double>() * tensor_d(t.w0, kInput, kHidden);
  h = (h.rowwise() + tensor_d(t.b0, 1, kHidden).row(0)).cwiseMax(0.0);
  h = h * tensor_d(t.w1, kHidden, kHidden);
  h = (h.rowwise() + tensor_d(t.b1, 1, kHidden).row(0)).cwiseMax(0.0);
  MatrixXdRow y = h * tensor_d(t.w2, kHidden, kOutput);
  y.rowwise() += tensor_d(t.b2, 1, kOutput).row(0);
  for (int r = 0; r < kRows; ++r) {
    const double mean = y.row(r).mean();
    const double variance = (y.row(r).array() - mean).square().mean();
    y.row(r) = ((y.row(r).array() - mean) / std::sqrt(variance + Mlp::kLayerNormEpsilon))
                   .matrix()
                   .cwiseProduct(tensor_d(t.scale, 1, kOutput).row(0)) +
               tensor_d(t.offset, 1, kOutput).row(0);
  }

  // Into a matrix of its own, and into the middle column block of a wider one.
  for (const int blocks_beside : {0, 1}) {
    SCOPED_TRACE(blocks_beside ? "column block" : "whole matrix");
    const RowMatrixXf before = random_matrix(rng, kRows, (1 + 2 * blocks_beside) * kOutput);
    auto run = [&](int threads) {
      const testing::ScopedEigenThreads scope(threads);
      Buffer first;
      MlpCache cache;
      RowMatrixXf wide = before;
      mlp.forward_dense(params.data(), x, first, cache,
                        wide.middleCols(blocks_beside * kOutput, kOutput));
      return wide;
    };
    const RowMatrixXf one = run(1);
    const auto out = one.middleCols(blocks_beside * kOutput, kOutput);
    EXPECT_LT((out.cast<double>() - y).cwiseAbs().maxCoeff(), 1e-3);
    if (blocks_beside) {
      EXPECT_EQ(one.leftCols(kOutput), before.leftCols(kOutput));
      EXPECT_EQ(one.rightCols(kOutput), before.rightCols(kOutput));
    }
    for (int threads = 2; threads <= 4; ++threads) EXPECT_EQ(run(threads), one) << threads;
  }
}

TEST(Parameters, InitialisationIsSeededAndScaledByFanIn) {
  ParameterLayout layout;
  const size_t w = layout.add("w", 400, 300, Init::kFanIn);
  const size_t b = layout.add("b", 1, 300, Init::kZeros);
  const size_t s = layout.add("s", 1, 300, Init::kOnes);
  std::vector<float> p1, p2, p3;
  layout.initialize(p1, 1);
  layout.initialize(p2, 1);
  layout.initialize(p3, 2);
  EXPECT_EQ(p1, p2);
  EXPECT_NE(p1, p3);
  const auto weights = tensor(p1.data(), w, 400, 300);
  // Truncated at ±2σ: the standard deviation is 0.88σ, σ = 1/sqrt(400).
  const float std = std::sqrt(weights.array().square().mean());
  EXPECT_NEAR(std, 0.88f / 20.0f, 0.002f);
  EXPECT_LE(weights.cwiseAbs().maxCoeff(), 2.0f / 20.0f);
  EXPECT_EQ(tensor(p1.data(), b, 1, 300).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ(tensor(p1.data(), s, 1, 300).minCoeff(), 1.0f);
}

TEST(Adam, DecaysTheLearningRateExponentiallyAndMinimisesAQuadratic) {
  Adam adam(2, {.learning_rate_start = 1e-1f, .learning_rate_end = 1e-2f, .decay_steps = 100});
  EXPECT_FLOAT_EQ(adam.learning_rate(), 1e-1f);
  std::vector<float> x = {3.0f, -2.0f}, g(2);
  for (int i = 0; i < 50; ++i) {
    g = {2 * x[0], 2 * x[1]};
    adam.update(x, g);
  }
  EXPECT_NEAR(adam.learning_rate(), 1e-1f * std::pow(0.1f, 0.5f), 1e-6f);  // halfway: 10^-1.5
  for (int i = 0; i < 450; ++i) {
    g = {2 * x[0], 2 * x[1]};
    adam.update(x, g);
  }
  EXPECT_FLOAT_EQ(adam.learning_rate(), 1e-2f);  // held after decay_steps
  EXPECT_LT(std::abs(x[0]) + std::abs(x[1]), 0.05f);
}

// A continuation restarts the decay: the start rate up to decay_start_step, the same curve
// shifted by it, and the end rate from decay_start_step + decay_steps on.
TEST(Adam, StartsTheDecayAtDecayStartStep) {
  Adam adam(1, {.learning_rate_start = 2e-4f,
                .learning_rate_end = 5e-5f,
                .decay_steps = 10,
                .decay_start_step = 1000});
  const auto rate_at = [&](std::int64_t step) {
    adam.set_step(step);
    return adam.learning_rate();
  };
  EXPECT_FLOAT_EQ(rate_at(0), 2e-4f);
  EXPECT_FLOAT_EQ(rate_at(1000), 2e-4f);
  EXPECT_NEAR(rate_at(1005), 1e-4f, 1e-9f);  // halfway: the geometric mean of 2e-4 and 5e-5
  EXPECT_FLOAT_EQ(rate_at(1010), 5e-5f);
  EXPECT_FLOAT_EQ(rate_at(5000), 5e-5f);
}

// The update runs on the threads in fixed blocks: the same bits for 1 and 3 threads, over
// several blocks and a partial one, and each parameter as Adam's formula in double precision
// gives it (to float rounding).
TEST(Adam, ThreadedUpdatesGiveTheSameBitsAsOneThreadAndFollowTheFormula) {
  const size_t n = 3 * Adam::kParallelBlock + 17;
  std::mt19937 rng(11);
  std::normal_distribution<float> normal;
  std::vector<float> start(n), g1(n), g2(n);
  for (size_t i = 0; i < n; ++i) start[i] = normal(rng), g1[i] = normal(rng), g2[i] = normal(rng);
  const AdamConfig config{
      .learning_rate_start = 1e-2f, .learning_rate_end = 1e-3f, .decay_steps = 10};
  std::vector<std::vector<float>> results;
  for (const int threads : {1, 3}) {
    const testing::ScopedThreads scope(threads);
    Adam adam(n, config);
    std::vector<float> x = start;
    adam.update(x, g1);
    adam.update(x, g2);
    results.push_back(x);
  }
  EXPECT_EQ(results[0], results[1]);
  const double rate0 = 1e-2, rate1 = 1e-2 * std::pow(0.1, 0.1);  // decay over 10 steps
  for (size_t i : {size_t(0), Adam::kParallelBlock - 1, Adam::kParallelBlock, n - 1}) {
    double x = start[i], m = 0, v = 0;
    const double grads[2] = {g1[i], g2[i]}, rates[2] = {rate0, rate1};
    for (int t = 1; t <= 2; ++t) {
      m = 0.9 * m + 0.1 * grads[t - 1];
      v = 0.999 * v + 0.001 * grads[t - 1] * grads[t - 1];
      const double m_hat = m / (1 - std::pow(0.9, t)), v_hat = v / (1 - std::pow(0.999, t));
      x -= rates[t - 1] * m_hat / (std::sqrt(v_hat) + 1e-8);
    }
    EXPECT_NEAR(results[0][i], x, 1e-6 * (1 + std::abs(x))) << "parameter " << i;
  }
}

}  // namespace
}  // namespace fignet
