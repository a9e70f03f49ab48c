// bf16 products (GemmPrecision::kBf16): the rounding to bfloat16 against the nearest of its two
// neighbouring bfloat16 values, and gemm()/gemm_bias() against double-precision products of the
// rounded operands, over the shapes the padding touches (blocks of rows around 32 and 256, sums
// around 256 and 2048), transposes, accumulation, column blocks and thread counts.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>

#include "../error_text.h"
#include "../scoped_threads.h"
#include "fignet/error.h"
#include "fignet/nn/gemm.h"
#include "gemm_oracle.h"
#include "nn/bfloat16.h"

namespace fignet {
namespace {

using detail::Bf16;
using detail::from_bf16;
using detail::to_bf16;
using testing::MatrixXdRow;
using testing::random_matrix;

// x's operand as the bf16 product sees it, in double.
MatrixXdRow rounded(const RowMatrixXf& x) {
  return x.unaryExpr([](float v) { return static_cast<double>(from_bf16(to_bf16(v))); });
}

TEST(Bfloat16, RoundsToTheNearestNeighbourTiesToEven) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> bits;
  for (int i = 0; i < 100000; ++i) {
    const float x = std::bit_cast<float>(bits(rng));
    if (!std::isfinite(x)) continue;
    // The two bfloat16 values around x: its upper half, and the next one away from zero. Past
    // the largest finite one, the next is infinity, which IEEE rounding places at ±2^128.
    const auto u = std::bit_cast<std::uint32_t>(x);
    const auto h = static_cast<Bf16>(u >> 16), next = static_cast<Bf16>(h + 1);
    const double below = from_bf16(h);
    const double above =
        (next & 0x7fffu) == 0x7f80u ? std::copysign(0x1p128, x) : double{from_bf16(next)};
    const double d_below = std::abs(x - below), d_above = std::abs(above - x);
    // A tie goes to the even one of the two.
    const Bf16 expected = d_below < d_above   ? h
                          : d_above < d_below ? next
                                              : static_cast<Bf16>(h % 2 == 0 ? h : next);
    ASSERT_EQ(to_bf16(x), expected) << std::hexfloat << x;
  }
  EXPECT_EQ(from_bf16(to_bf16(1.0f)), 1.0f);
  EXPECT_EQ(from_bf16(to_bf16(-0.0f)), -0.0f);
  EXPECT_EQ(from_bf16(to_bf16(std::numeric_limits<float>::infinity())),
            std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(from_bf16(to_bf16(std::numeric_limits<float>::quiet_NaN()))));
  // A NaN whose payload is in the lower half only must not become infinity.
  EXPECT_TRUE(std::isnan(from_bf16(to_bf16(std::bit_cast<float>(0x7f800001u)))));
  // 1 + 2^-8 lies halfway between 1 and 1 + 2^-7: to the even one, 1.
  EXPECT_EQ(from_bf16(to_bf16(1.0f + 0x1p-8f)), 1.0f);
  EXPECT_EQ(from_bf16(to_bf16(1.0f + 0x1p-8f + 0x1p-20f)), 1.0f + 0x1p-7f);
}

TEST(Bfloat16, BulkRoundingGivesTheSameBitsAsOneByOne) {
  // The processor's conversion instruction (where it has one) for 16 at a time, then the tail.
  const RowMatrixXf x = 1000.0f * random_matrix(1, 1003, 3);
  std::vector<Bf16> bulk(x.size());
  detail::round_to_bf16(x.data(), bulk.data(), x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) ASSERT_EQ(bulk[i], to_bf16(x(0, i))) << i;
}

TEST(Bfloat16, CopiesPadWithZeros) {
  const RowMatrixXf wide = random_matrix(5, 9, 4);
  std::vector<Bf16> out(8 * 6, 0xffff);
  detail::copy_to_bf16(wide.middleCols(2, 4), 8, 6, out.data());
  for (int r = 0; r < 8; ++r) {
    for (int c = 0; c < 6; ++c) {
      const Bf16 expected = r < 5 && c < 4 ? to_bf16(wide(r, 2 + c)) : Bf16{0};
      EXPECT_EQ(out[r * 6 + c], expected) << r << "," << c;
    }
  }
}

// Sets bf16 products for a test and restores f32 after; skips where this machine has none.
class Bf16Gemm : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why_not = gemm_precision_unavailable(GemmPrecision::kBf16);
    if (!why_not.empty()) GTEST_SKIP() << why_not;
    set_gemm_precision(GemmPrecision::kBf16);
  }
  void TearDown() override { set_gemm_precision(GemmPrecision::kF32); }
};

TEST_F(Bf16Gemm, MatchesADoubleProductOfTheRoundedOperands) {
  // Rows around the padding quanta (32, 256) and sums around 256 and 2048 (the blocks of sums).
  const testing::ProductShape shapes[] = {{1, 1, 1},     {7, 5, 3},    {33, 192, 64},
                                          {256, 64, 64}, {257, 64, 3}, {300, 2049, 5},
                                          {64, 255, 48}, {600, 64, 64}};
  testing::expect_gemm_matches_double(shapes, rounded);
}

TEST_F(Bf16Gemm, DiffersFromF32ByTheOperandsRounding) {
  // Not the f32 product: the operands were rounded (a test that would pass on f32 products
  // proves nothing about bf16 ones). Relative error per operand <= 2^-9.
  const RowMatrixXf a = random_matrix(512, 64, 11), b = random_matrix(64, 64, 12);
  RowMatrixXf c(512, 64);
  gemm(a, Transpose::kNo, b, Transpose::kNo, c, false);
  const MatrixXdRow exact = a.cast<double>() * b.cast<double>();
  const double error = (c.cast<double>() - exact).cwiseAbs().maxCoeff();
  EXPECT_GT(error, 1e-4);
  EXPECT_LT(error, 64 * 2.0 * 0x1p-9);
}

TEST_F(Bf16Gemm, BiasAndReluOnColumnBlocksMatchADoubleLinearLayer) {
  // A partial block of rows (padded), full blocks, and column blocks of wider matrices (c's row
  // stride above its width), as the MLPs' first layers write them.
  for (const int m : {40, 256, 549}) {
    SCOPED_TRACE(::testing::Message() << m << " rows");
    const RowMatrixXf wide_a = random_matrix(m, 3 * 64, 20), b = random_matrix(64, 48, 21);
    const RowMatrixXf bias = random_matrix(1, 48, 22);
    RowMatrixXf wide_c = random_matrix(m, 3 * 48, 23);
    const RowMatrixXf before = wide_c;
    gemm_bias(wide_a.middleCols(64, 64), b, Transpose::kNo, bias.data(), Activation::kRelu,
              wide_c.middleCols(48, 48));
    MatrixXdRow expected = rounded(RowMatrixXf(wide_a.middleCols(64, 64))) * rounded(b);
    expected.rowwise() += bias.cast<double>().row(0);
    expected = expected.cwiseMax(0.0);
    EXPECT_LT((wide_c.middleCols(48, 48).cast<double>() - expected).cwiseAbs().maxCoeff(),
              testing::product_tolerance(64));
    EXPECT_EQ(wide_c.leftCols(48), before.leftCols(48));
    EXPECT_EQ(wide_c.rightCols(48), before.rightCols(48));
  }
}

TEST_F(Bf16Gemm, GivesTheSameBitsForAnyThreadCount) {
  const RowMatrixXf a = random_matrix(2401, 64, 30), b = random_matrix(64, 96, 31);
  const RowMatrixXf g = random_matrix(2401, 96, 32);
  auto run = [&](int threads) {
    const testing::ScopedEigenThreads scope(threads);
    RowMatrixXf rows(a.rows(), b.cols()), sums(a.cols(), g.cols());
    gemm(a, Transpose::kNo, b, Transpose::kNo, rows, false);
    gemm(a, Transpose::kYes, g, Transpose::kNo, sums, false);
    return std::pair{rows, sums};
  };
  const auto one = run(1);
  for (int threads = 2; threads <= 3; ++threads) {
    const auto many = run(threads);
    EXPECT_EQ(many.first, one.first) << threads;
    EXPECT_EQ(many.second, one.second) << threads;
  }
}

TEST_F(Bf16Gemm, TheDescriptionSaysBf16) {
  EXPECT_NE(gemm_description().find("bf16"), std::string::npos) << gemm_description();
}

TEST_F(Bf16Gemm, EigenIsRefusedWhileBf16IsOn) {
  // Eigen has no bf16 products: switching to it would make them f32 without a word.
  const std::string refusal =
      testing::error_of<ConfigError>([] { set_gemm_engine(GemmEngine::kEigen); });
  EXPECT_NE(refusal.find("set_gemm_precision"), std::string::npos) << refusal;
  EXPECT_EQ(gemm_engine(), GemmEngine::kOneDnn);
  EXPECT_EQ(gemm_precision(), GemmPrecision::kBf16);
  // Back to f32 first, and the switch is allowed.
  set_gemm_precision(GemmPrecision::kF32);
  set_gemm_engine(GemmEngine::kEigen);
  EXPECT_EQ(gemm_engine(), GemmEngine::kEigen);
  set_gemm_engine(GemmEngine::kOneDnn);
}

TEST(GemmPrecision, Bf16IsRefusedWithAReasonWhereItCannotRun) {
  EXPECT_EQ(gemm_precision(), GemmPrecision::kF32);
  EXPECT_EQ(gemm_precision_unavailable(GemmPrecision::kF32), "");
  // On Eigen always; elsewhere where oneDNN has no bf16 instructions.
  const GemmEngine engine = gemm_engine();
  set_gemm_engine(GemmEngine::kEigen);
  EXPECT_NE(gemm_precision_unavailable(GemmPrecision::kBf16).find("Eigen"), std::string::npos);
  const std::string refusal =
      testing::error_of<ConfigError>([] { set_gemm_precision(GemmPrecision::kBf16); });
  EXPECT_NE(refusal.find("bf16"), std::string::npos) << refusal;
  EXPECT_EQ(gemm_precision(), GemmPrecision::kF32);
  set_gemm_engine(engine);
}

}  // namespace
}  // namespace fignet
