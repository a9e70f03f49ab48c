#include "fignet/nn/ops.h"

#include "fignet/nn/gemm.h"

namespace fignet {

void gather_add(const ConstMatrixRef& src, IndexSpan index, MatrixRef out) {
  for (Eigen::Index e = 0; e < index.count; ++e) out.row(e) += src.row(index[e]);
}

void scatter_add(const ConstMatrixRef& src, IndexSpan index, MatrixRef out) {
  for (Eigen::Index e = 0; e < index.count; ++e) out.row(index[e]) += src.row(e);
}

void add_product(const ConstMatrixRef& x, const ConstMatrixRef& w, MatrixRef z) {
  gemm(x, Transpose::kNo, w, Transpose::kNo, z, /*accumulate=*/true);
}

void add_gathered_product(const ConstMatrixRef& x, const ConstMatrixRef& w, IndexSpan index,
                          MatrixRef z, Buffer& scratch) {
  if (index.count == 0) return;
  MatrixView per_node = scratch.view(x.rows(), w.cols());
  gemm(x, Transpose::kNo, w, Transpose::kNo, per_node, /*accumulate=*/false);
  gather_add(per_node, index, z);
}

void backprop_product(const ConstMatrixRef& x, const ConstMatrixRef& w, const ConstMatrixRef& dz,
                      MatrixRef dw, MatrixRef* dx) {
  if (x.rows() == 0) return;
  gemm(x, Transpose::kYes, dz, Transpose::kNo, dw, /*accumulate=*/true);
  if (dx) gemm(dz, Transpose::kNo, w, Transpose::kYes, *dx, /*accumulate=*/true);
}

void backprop_gathered_product(const ConstMatrixRef& x, const ConstMatrixRef& w, IndexSpan index,
                               const ConstMatrixRef& dz, MatrixRef dw, MatrixRef* dx,
                               Buffer& scratch) {
  if (index.count == 0) return;
  MatrixView per_node = scratch.zeros(x.rows(), w.cols());
  scatter_add(dz, index, per_node);
  gemm(x, Transpose::kYes, per_node, Transpose::kNo, dw, /*accumulate=*/true);
  if (dx) gemm(per_node, Transpose::kNo, w, Transpose::kYes, *dx, /*accumulate=*/true);
}

}  // namespace fignet
