// Reusable float storage viewed as row-major matrices. A Buffer keeps its capacity across calls,
// so per-step activations of graphs of varying size allocate only while they grow.
#pragma once

#include <vector>

#include "fignet/geometry/types.h"

namespace fignet {

using MatrixView = Eigen::Map<RowMatrixXf>;
using ConstMatrixView = Eigen::Map<const RowMatrixXf>;
// Any row-major float matrix or block of one (a column range of a wider matrix included).
using MatrixRef = Eigen::Ref<RowMatrixXf, 0, Eigen::OuterStride<>>;
using ConstMatrixRef = Eigen::Ref<const RowMatrixXf, 0, Eigen::OuterStride<>>;

class Buffer {
 public:
  // A rows x cols view of the buffer (contents unspecified).
  MatrixView view(Eigen::Index rows, Eigen::Index cols) {
    if (data_.size() < static_cast<size_t>(rows * cols)) data_.resize(rows * cols);
    rows_ = rows, cols_ = cols;
    return {data_.data(), rows, cols};
  }
  MatrixView zeros(Eigen::Index rows, Eigen::Index cols) {
    MatrixView m = view(rows, cols);
    m.setZero();
    return m;
  }
  // The last view's shape.
  MatrixView get() { return {data_.data(), rows_, cols_}; }
  ConstMatrixView get() const { return {data_.data(), rows_, cols_}; }
  ConstMatrixView cget() const { return get(); }

 private:
  // Never empty: a view of zero rows still points at storage, so column blocks of it (which add
  // an offset to the pointer) are defined behaviour, not arithmetic on null (UBSan,
  // fuzz_model_file).
  AlignedFloats data_ = AlignedFloats(1);
  Eigen::Index rows_ = 0, cols_ = 0;
};

}  // namespace fignet
