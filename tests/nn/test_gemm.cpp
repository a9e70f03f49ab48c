// gemm() against a double-precision product, for every engine the build has, every transpose,
// assignment and accumulation, column blocks of wider matrices and empty dimensions; gemm_bias()
// against a double-precision Linear layer.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "../scoped_threads.h"
#include "fignet/error.h"
#include "fignet/nn/gemm.h"
#include "gemm_oracle.h"

namespace fignet {
namespace {

using testing::MatrixXdRow;
using testing::random_matrix;

// Restores the engine a test changed.
class EngineScope {
 public:
  explicit EngineScope(GemmEngine engine) : previous_(gemm_engine()) { set_gemm_engine(engine); }
  ~EngineScope() { set_gemm_engine(previous_); }

 private:
  GemmEngine previous_;
};

class Gemm : public ::testing::TestWithParam<GemmEngine> {
 protected:
  void SetUp() override {
    if (!gemm_engine_available(GetParam())) GTEST_SKIP() << "this build has no oneDNN";
  }
};

TEST_P(Gemm, MatchesADoublePrecisionProductForEveryTransposeAndShape) {
  const EngineScope scope(GetParam());
  // Shapes of the network (thin and wide, K from 3 to hundreds) and odd sizes.
  const testing::ProductShape shapes[] = {
      {1, 1, 1}, {7, 5, 3}, {400, 64, 64}, {33, 192, 64}, {64, 1000, 3}};
  testing::expect_gemm_matches_double(shapes, testing::as_given);
}

TEST_P(Gemm, WorksOnColumnBlocksOfWiderMatrices) {
  const EngineScope scope(GetParam());
  // The face-edge latents are [q0 q1 q2], three column blocks of one 3L-wide matrix.
  const RowMatrixXf wide_a = random_matrix(50, 3 * 16, 1), b = random_matrix(16, 8, 2);
  RowMatrixXf wide_c = random_matrix(50, 3 * 8, 3);
  const RowMatrixXf before = wide_c;
  gemm(wide_a.middleCols(16, 16), Transpose::kNo, b, Transpose::kNo, wide_c.middleCols(8, 8), true);
  const RowMatrixXf expected = before.middleCols(8, 8) + wide_a.middleCols(16, 16) * b;
  EXPECT_LT((wide_c.middleCols(8, 8) - expected).cwiseAbs().maxCoeff(), 1e-5);
  // Columns outside the block are untouched.
  EXPECT_EQ(wide_c.leftCols(8), before.leftCols(8));
  EXPECT_EQ(wide_c.rightCols(8), before.rightCols(8));
}

TEST_P(Gemm, EmptyInnerDimensionGivesZerosOrLeavesTheSum) {
  const EngineScope scope(GetParam());
  const RowMatrixXf a(4, 0), b(0, 3);
  RowMatrixXf c = random_matrix(4, 3, 1);
  const RowMatrixXf before = c;
  gemm(a, Transpose::kNo, b, Transpose::kNo, c, true);
  EXPECT_EQ(c, before);
  gemm(a, Transpose::kNo, b, Transpose::kNo, c, false);
  EXPECT_EQ(c, RowMatrixXf::Zero(4, 3));
  RowMatrixXf empty(0, 3);
  gemm(RowMatrixXf(0, 5), Transpose::kNo, random_matrix(5, 3, 2), Transpose::kNo, empty, false);
}

// gemm(op_a(a)·op_b(b)) at 1 to 4 threads (Eigen's setting), for both op_b and with and
// without accumulating into `start`: within `tolerance` of the double product at one thread, and
// the same bits at every other count.
void expect_same_bits_for_any_thread_count(const RowMatrixXf& a, Transpose op_a,
                                           const RowMatrixXf& b, const RowMatrixXf& start,
                                           double tolerance) {
  const RowMatrixXf bt = b.transpose();
  auto run = [&](int threads, Transpose op_b, bool accumulate) {
    const testing::ScopedEigenThreads scope(threads);
    RowMatrixXf c = start;
    gemm(a, op_a, op_b == Transpose::kNo ? b : bt, op_b, c, accumulate);
    return c;
  };
  const MatrixXdRow exact = op_a == Transpose::kNo
                                ? MatrixXdRow(a.cast<double>() * b.cast<double>())
                                : MatrixXdRow(a.cast<double>().transpose() * b.cast<double>());
  for (Transpose op_b : {Transpose::kNo, Transpose::kYes}) {
    for (bool accumulate : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "op_b transposed " << (op_b == Transpose::kYes)
                                        << ", accumulate " << accumulate);
      const RowMatrixXf one = run(1, op_b, accumulate);
      const MatrixXdRow expected = accumulate ? MatrixXdRow(exact + start.cast<double>()) : exact;
      EXPECT_LT((one.cast<double>() - expected).cwiseAbs().maxCoeff(), tolerance);
      for (int threads = 2; threads <= 4; ++threads) {
        EXPECT_EQ(run(threads, op_b, accumulate), one) << threads << " threads";
      }
    }
  }
}

// Weight gradients (aᵀ·b) sum over thousands of rows; threads share that sum, and the result must
// be the same bits for any thread count (bit-exact resume on another machine's core count).
TEST_P(Gemm, SumsOverRowsGiveTheSameBitsForAnyThreadCount) {
  const EngineScope scope(GetParam());
  expect_same_bits_for_any_thread_count(random_matrix(2500, 64, 1), Transpose::kYes,
                                        random_matrix(2500, 48, 2), random_matrix(64, 48, 3),
                                        1e-5 * 2500);
}

// Row products (a·b) of a scene's thousands of rows are shared among threads too: each row's
// bits must not depend on how many (oneDNN's own threading on avx2 kernels changes them).
TEST_P(Gemm, RowProductsGiveTheSameBitsForAnyThreadCount) {
  const EngineScope scope(GetParam());
  for (const Eigen::Index k : {64, 384}) {
    SCOPED_TRACE(::testing::Message() << "k = " << k);
    expect_same_bits_for_any_thread_count(random_matrix(2401, k, 4), Transpose::kNo,
                                          random_matrix(k, 128, 5), random_matrix(2401, 128, 6),
                                          1e-5 * k);
  }
}

// A Linear layer's product with its bias and activation, the rows of full blocks (which oneDNN
// runs through its matmul primitive with fused post-ops) and of a partial last block (sgemm and a
// pass) alike: within float rounding of the double product, then the bias, then max(·, 0).
TEST_P(Gemm, BiasAndReluMatchADoublePrecisionLinearLayer) {
  const EngineScope scope(GetParam());
  const int shapes[][3] = {{256, 64, 64}, {549, 64, 64}, {300, 128, 3}, {77, 3, 64}, {512, 16, 8}};
  unsigned seed = 100;
  for (const auto& shape : shapes) {
    const int m = shape[0], k = shape[1], n = shape[2];
    for (Transpose tb : {Transpose::kNo, Transpose::kYes}) {
      for (Activation activation : {Activation::kNone, Activation::kRelu}) {
        SCOPED_TRACE(::testing::Message()
                     << m << "x" << k << "x" << n << " tb " << (tb == Transpose::kYes) << " relu "
                     << (activation == Activation::kRelu));
        const RowMatrixXf a = random_matrix(m, k, seed++);
        const RowMatrixXf b =
            tb == Transpose::kNo ? random_matrix(k, n, seed++) : random_matrix(n, k, seed++);
        const RowMatrixXf bias = random_matrix(1, n, seed++);
        const MatrixXdRow b_op = tb == Transpose::kNo ? MatrixXdRow(b.cast<double>())
                                                      : MatrixXdRow(b.cast<double>().transpose());
        MatrixXdRow expected = a.cast<double>() * b_op;
        expected.rowwise() += bias.cast<double>().row(0);
        if (activation == Activation::kRelu) expected = expected.cwiseMax(0.0);
        RowMatrixXf c = random_matrix(m, n, seed++);  // overwritten, never read
        gemm_bias(a, b, tb, bias.data(), activation, c);
        EXPECT_LT((c.cast<double>() - expected).cwiseAbs().maxCoeff(),
                  testing::product_tolerance(k));
      }
    }
  }
}

// The MLPs' products read and write column blocks of wider matrices too; the bias and ReLU then
// touch the block's columns only.
TEST_P(Gemm, BiasAndReluWorkOnColumnBlocksOfWiderMatrices) {
  const EngineScope scope(GetParam());
  const RowMatrixXf wide_a = random_matrix(300, 3 * 16, 1), b = random_matrix(16, 8, 2);
  const RowMatrixXf bias = random_matrix(1, 8, 3);
  RowMatrixXf wide_c = random_matrix(300, 3 * 8, 4);
  const RowMatrixXf before = wide_c;
  gemm_bias(wide_a.middleCols(16, 16), b, Transpose::kNo, bias.data(), Activation::kRelu,
            wide_c.middleCols(8, 8));
  RowMatrixXf expected = wide_a.middleCols(16, 16) * b;
  expected.rowwise() += bias.row(0);
  expected = expected.cwiseMax(0.0f);
  EXPECT_LT((wide_c.middleCols(8, 8) - expected).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_EQ(wide_c.leftCols(8), before.leftCols(8));
  EXPECT_EQ(wide_c.rightCols(8), before.rightCols(8));
}

// Each row's bits depend on its block, not on how many threads share the blocks.
TEST_P(Gemm, BiasAndReluGiveTheSameBitsForAnyThreadCount) {
  const EngineScope scope(GetParam());
  const RowMatrixXf a = random_matrix(1500, 64, 5), b = random_matrix(64, 64, 6);
  const RowMatrixXf bias = random_matrix(1, 64, 7);
  auto run = [&](int threads) {
    const testing::ScopedEigenThreads scope(threads);
    RowMatrixXf c(a.rows(), b.cols());
    gemm_bias(a, b, Transpose::kNo, bias.data(), Activation::kRelu, c);
    return c;
  };
  const RowMatrixXf one = run(1);
  for (int threads = 2; threads <= 4; ++threads) EXPECT_EQ(run(threads), one) << threads;
}

// Row passes fused into a product: the prologue runs on every row of a before the product reads
// it (here it doubles a's rows, written in place), the epilogue on every row of c after its
// product, bias and ReLU (here it squares them), each row exactly once: the result is the
// unfused computation's, bit for bit, for any thread count, over full blocks and a partial one.
TEST_P(Gemm, RowPassesRunOnEveryRowOnceBeforeAndAfterItsProduct) {
  const EngineScope scope(GetParam());
  const RowMatrixXf source = random_matrix(700, 64, 8), b = random_matrix(64, 32, 9);
  const RowMatrixXf bias = random_matrix(1, 32, 10);
  RowMatrixXf expected(source.rows(), b.cols());
  gemm_bias(2.0f * source, b, Transpose::kNo, bias.data(), Activation::kRelu, expected);
  expected = expected.cwiseProduct(expected);

  struct Passes {
    const RowMatrixXf* source;
    RowMatrixXf* a;
    RowMatrixXf* c;
    std::vector<int>* visits;  // per row: +1 for each prologue, +10 for each epilogue
  };
  auto prologue = [](const void* context, Eigen::Index first, Eigen::Index rows) {
    const auto& p = *static_cast<const Passes*>(context);
    p.a->middleRows(first, rows) = 2.0f * p.source->middleRows(first, rows);
    for (Eigen::Index r = first; r < first + rows; ++r) (*p.visits)[r] += 1;
  };
  auto epilogue = [](const void* context, Eigen::Index first, Eigen::Index rows) {
    const auto& p = *static_cast<const Passes*>(context);
    p.c->middleRows(first, rows) = p.c->middleRows(first, rows).cwiseAbs2();
    for (Eigen::Index r = first; r < first + rows; ++r) (*p.visits)[r] += 10;
  };
  for (int threads = 1; threads <= 4; ++threads) {
    RowMatrixXf a = RowMatrixXf::Constant(source.rows(), source.cols(), 1e30f);  // unread until set
    RowMatrixXf c(source.rows(), b.cols());
    std::vector<int> visits(source.rows(), 0);
    const Passes passes{&source, &a, &c, &visits};
    {
      const testing::ScopedEigenThreads scope(threads);
      gemm_bias(a, b, Transpose::kNo, bias.data(), Activation::kRelu, c, {+prologue, &passes},
                {+epilogue, &passes});
    }
    EXPECT_EQ(c, expected) << threads << " threads";
    EXPECT_EQ(std::count(visits.begin(), visits.end(), 11), source.rows()) << threads;
  }
}

INSTANTIATE_TEST_SUITE_P(Engines, Gemm, ::testing::Values(GemmEngine::kEigen, GemmEngine::kOneDnn),
                         [](const auto& info) { return gemm_engine_name(info.param); });

TEST(GemmEngine, EigenIsAlwaysThereAndTheDescriptionNamesTheEngine) {
  EXPECT_TRUE(gemm_engine_available(GemmEngine::kEigen));
  const EngineScope scope(GemmEngine::kEigen);
  EXPECT_EQ(gemm_description().rfind("Eigen ", 0), 0u) << gemm_description();
  if (gemm_engine_available(GemmEngine::kOneDnn)) {
    set_gemm_engine(GemmEngine::kOneDnn);
    EXPECT_EQ(gemm_description().rfind("oneDNN ", 0), 0u) << gemm_description();
    // Says whether the full blocks run on brgemm kernels or everything on sgemm.
    EXPECT_TRUE(gemm_description().find("matmul primitive (brg") != std::string::npos ||
                gemm_description().find("on its sgemm") != std::string::npos)
        << gemm_description();
  } else {
    EXPECT_THROW(set_gemm_engine(GemmEngine::kOneDnn), ConfigError);
  }
}

}  // namespace
}  // namespace fignet
