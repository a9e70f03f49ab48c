#include "fignet/nn/ops.h"

namespace fignet {

void gather_add(const ConstMatrixRef& src, IndexSpan index, MatrixRef out) {
  for (Eigen::Index e = 0; e < index.count; ++e) out.row(e) += src.row(index[e]);
}

void scatter_add(const ConstMatrixRef& src, IndexSpan index, MatrixRef out) {
  for (Eigen::Index e = 0; e < index.count; ++e) out.row(index[e]) += src.row(e);
}

void add_product(const ConstMatrixRef& x, const ConstMatrixRef& w, MatrixRef z) {
  if (x.rows() > 0) z.noalias() += x * w;
}

void add_gathered_product(const ConstMatrixRef& x, const ConstMatrixRef& w, IndexSpan index,
                          MatrixRef z, Buffer& scratch) {
  if (index.count == 0) return;
  MatrixView per_node = scratch.view(x.rows(), w.cols());
  per_node.noalias() = x * w;
  gather_add(per_node, index, z);
}

void backprop_product(const ConstMatrixRef& x, const ConstMatrixRef& w, const ConstMatrixRef& dz,
                      MatrixRef dw, MatrixRef* dx) {
  if (x.rows() == 0) return;
  dw.noalias() += x.transpose() * dz;
  if (dx) dx->noalias() += dz * w.transpose();
}

void backprop_gathered_product(const ConstMatrixRef& x, const ConstMatrixRef& w, IndexSpan index,
                               const ConstMatrixRef& dz, MatrixRef dw, MatrixRef* dx,
                               Buffer& scratch) {
  if (index.count == 0) return;
  MatrixView per_node = scratch.zeros(x.rows(), w.cols());
  scatter_add(dz, index, per_node);
  dw.noalias() += x.transpose() * per_node;
  if (dx) dx->noalias() += per_node * w.transpose();
}

}  // namespace fignet
