// oneDNN's matmul primitive for gemm()'s blocks of rows, with a product's bias and ReLU fused as
// post-ops. Its brgemm kernels (AVX-512 and newer processors) run the network's block shapes
// 10-15 % faster than oneDNN's sgemm, and the fused epilogue saves a pass over the output; but a
// primitive is compiled for one shape, so only the blocks of the fixed row count come here (the
// partial last block of a product goes through sgemm, whose kernels take any shape).
#pragma once

#include <omp.h>

#include <string>

#include "fignet/nn/buffer.h"
#include "fignet/nn/gemm.h"

namespace fignet::detail {

// oneDNN's OpenMP runtime takes omp_get_max_threads() both when it plans a primitive's work and
// when it runs it (sgemm included): one while this lives, the caller's setting restored after.
class OneOmpThread {
 public:
  OneOmpThread() : before_(omp_get_max_threads()) {
    if (before_ != 1) omp_set_num_threads(1);
  }
  ~OneOmpThread() {
    if (before_ != 1) omp_set_num_threads(before_);
  }
  OneOmpThread(const OneOmpThread&) = delete;
  OneOmpThread& operator=(const OneOmpThread&) = delete;

 private:
  int before_;
};

// c (+)= a·op_b(b), then c = act(c + bias) when `bias` is given (not with `accumulate`), on the
// calling thread alone. Each thread compiles a primitive per shape, strides and epilogue at its
// first use and keeps it: a steady-state step neither compiles nor allocates. Returns false,
// leaving c as it was, where oneDNN has no brgemm kernel for the product on this processor (it
// would run its sgemm inside the primitive, at best as fast as the caller's). Throws Error with
// oneDNN's status and the shape when oneDNN fails.
bool onednn_matmul_one_thread(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b,
                              MatrixRef c, bool accumulate, const float* bias,
                              Activation activation);

// oneDNN's implementation of the full blocks' primitive on this processor, e.g. "brg:avx512_core"
// (brgemm kernels) or "gemm:jit" (its sgemm inside: gemm() then calls sgemm itself).
std::string onednn_block_kernel();

}  // namespace fignet::detail
