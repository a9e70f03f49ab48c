// The product tests' oracle: gemm() against a double-precision product of the operands as the
// product is meant to see them (as given, or rounded to bfloat16), for every transpose, with and
// without accumulation.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <span>

#include "fignet/nn/gemm.h"

namespace fignet::testing {

using MatrixXdRow = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

inline RowMatrixXf random_matrix(Eigen::Index rows, Eigen::Index cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  RowMatrixXf m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = u(rng);
  return m;
}

// How far a float32 sum of k products of numbers <= 1 in magnitude may stray from the double one:
// its error grows like k·eps.
inline double product_tolerance(Eigen::Index k) {
  return 1e-5 * static_cast<double>(k + 10);
}

inline MatrixXdRow as_given(const RowMatrixXf& x) {
  return x.cast<double>();
}

struct ProductShape {
  int m, k, n;
};

// For each m x k x n shape: c (+)= op_a(a)·op_b(b) on random operands in [-1, 1] within
// product_tolerance(k) of the double product of operand(a) and operand(b).
template <class Operand>
void expect_gemm_matches_double(std::span<const ProductShape> shapes, Operand operand) {
  unsigned seed = 1;
  for (const auto& [m, k, n] : shapes) {
    for (Transpose ta : {Transpose::kNo, Transpose::kYes}) {
      for (Transpose tb : {Transpose::kNo, Transpose::kYes}) {
        for (bool accumulate : {false, true}) {
          SCOPED_TRACE(::testing::Message()
                       << m << "x" << k << "x" << n << " ta " << (ta == Transpose::kYes) << " tb "
                       << (tb == Transpose::kYes) << " acc " << accumulate);
          const RowMatrixXf a =
              ta == Transpose::kNo ? random_matrix(m, k, seed++) : random_matrix(k, m, seed++);
          const RowMatrixXf b =
              tb == Transpose::kNo ? random_matrix(k, n, seed++) : random_matrix(n, k, seed++);
          RowMatrixXf c = random_matrix(m, n, seed++);
          const MatrixXdRow a_op =
              ta == Transpose::kNo ? operand(a) : MatrixXdRow(operand(a).transpose());
          const MatrixXdRow b_op =
              tb == Transpose::kNo ? operand(b) : MatrixXdRow(operand(b).transpose());
          const MatrixXdRow expected =
              (accumulate ? MatrixXdRow(c.cast<double>()) : MatrixXdRow::Zero(m, n)) + a_op * b_op;
          gemm(a, ta, b, tb, c, accumulate);
          EXPECT_LT((c.cast<double>() - expected).cwiseAbs().maxCoeff(), product_tolerance(k));
        }
      }
    }
  }
}

}  // namespace fignet::testing
