// Graph-network kernels and their adjoints: gathers, segment sums, and products whose
// concatenated inputs are split into blocks. A Linear over a concatenation [a, b, c] equals
// a·W_a + b·W_b + c·W_c; a block of per-node latents is multiplied once per node and then
// gathered per edge where the edges outnumber the nodes (mesh edges), and gathered first and
// multiplied once per edge where they do not (face-face edges: a few contacts among many nodes).
#pragma once

#include <cstdint>

#include "fignet/nn/buffer.h"

namespace fignet {

// Row e of an edge set reads node index(e) = data[e * stride + offset] (stride 3 addresses the
// j-th sender or receiver of face-face edges).
struct IndexSpan {
  const std::int32_t* data = nullptr;
  Eigen::Index count = 0;
  int stride = 1;
  int offset = 0;
  std::int32_t operator[](Eigen::Index e) const { return data[e * stride + offset]; }
};

// out.row(e) += src.row(index[e]) for every e.
void gather_add(const ConstMatrixRef& src, IndexSpan index, MatrixRef out);
// out.row(index[e]) += src.row(e): the segment sum, and the adjoint of gather_add.
void scatter_add(const ConstMatrixRef& src, IndexSpan index, MatrixRef out);

// z += x·w.
void add_product(const ConstMatrixRef& x, const ConstMatrixRef& w, MatrixRef z);
// z.row(e) += (x·w).row(index[e]): x·w computed once per row of x into `scratch` when the index
// has at least as many entries as x has rows, else x's rows gathered into `scratch` and multiplied.
void add_gathered_product(const ConstMatrixRef& x, const ConstMatrixRef& w, IndexSpan index,
                          MatrixRef z, Buffer& scratch);

// Adjoints of add_product: dw += xᵀ·dz and, when dx is given, dx += dz·wᵀ.
void backprop_product(const ConstMatrixRef& x, const ConstMatrixRef& w, const ConstMatrixRef& dz,
                      MatrixRef dw, MatrixRef* dx);
// Adjoints of add_gathered_product, by the same choice: the edge gradients summed per node first
// (`scratch`), or the gathered rows' gradients scattered back to their nodes.
void backprop_gathered_product(const ConstMatrixRef& x, const ConstMatrixRef& w, IndexSpan index,
                               const ConstMatrixRef& dz, MatrixRef dw, MatrixRef* dx,
                               Buffer& scratch);

}  // namespace fignet
