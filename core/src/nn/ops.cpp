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

namespace {

// x's rows in the order the index reads them: the gathered input of an edge set.
MatrixView gather_rows(const ConstMatrixRef& x, IndexSpan index, Buffer& scratch) {
  MatrixView gathered = scratch.view(index.count, x.cols());
  for (Eigen::Index e = 0; e < index.count; ++e) gathered.row(e) = x.row(index[e]);
  return gathered;
}

// Multiplying each node once pays off only where the edges outnumber the nodes (mesh edges); a
// set of few edges over many nodes (face-face edges, a scene's few contacts among its mesh
// nodes) is cheaper gathered first and multiplied per edge.
bool multiply_per_node(const ConstMatrixRef& x, IndexSpan index) {
  return index.count >= x.rows();
}

}  // namespace

void add_gathered_product(const ConstMatrixRef& x, const ConstMatrixRef& w, IndexSpan index,
                          MatrixRef z, Buffer& scratch) {
  if (index.count == 0) return;
  if (!multiply_per_node(x, index)) {
    gemm(gather_rows(x, index, scratch), Transpose::kNo, w, Transpose::kNo, z,
         /*accumulate=*/true);
    return;
  }
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
  if (!multiply_per_node(x, index)) {
    // dw += gatheredᵀ·dz, then dx += scatter(dz·wᵀ) through the same scratch.
    gemm(gather_rows(x, index, scratch), Transpose::kYes, dz, Transpose::kNo, dw,
         /*accumulate=*/true);
    if (!dx) return;
    MatrixView d_gathered = scratch.view(index.count, x.cols());
    gemm(dz, Transpose::kNo, w, Transpose::kYes, d_gathered, /*accumulate=*/false);
    scatter_add(d_gathered, index, *dx);
    return;
  }
  MatrixView per_node = scratch.zeros(x.rows(), w.cols());
  scatter_add(dz, index, per_node);
  gemm(x, Transpose::kYes, per_node, Transpose::kNo, dw, /*accumulate=*/true);
  if (dx) gemm(per_node, Transpose::kNo, w, Transpose::kYes, *dx, /*accumulate=*/true);
}

}  // namespace fignet
