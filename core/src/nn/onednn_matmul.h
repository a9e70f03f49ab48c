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
#include "nn/bfloat16.h"

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

// Whether oneDNN runs bfloat16 products on bf16 instructions here (AVX512-BF16 or AMX): its bf16
// kernels elsewhere convert in software, slower than its f32 ones.
bool onednn_bf16_available();

// The bf16 products (GemmPrecision::kBf16) on the calling thread alone: both operands rounded to
// bfloat16, the sums in float32, c in float32. Primitives are compiled per shape, so row counts
// are padded (zero rows that add nothing): a block of rows to a multiple of kBf16RowQuantum, a
// weight gradient's sum to a multiple of kBf16SumQuantum; a steady-state step then reuses a few
// shapes and neither compiles nor allocates. Throws Error with oneDNN's status when it fails.
constexpr Eigen::Index kBf16RowQuantum = 32;
constexpr Eigen::Index kBf16SumQuantum = 256;

// op_b(b) as the bf16 operand of row products: op_b's storage (k x n, or n x k transposed), dense.
struct Bf16Weights {
  const Bf16* data = nullptr;
  Eigen::Index k = 0, n = 0;
  Transpose op = Transpose::kNo;
};

// c (+)= a·op_b(b), then c = act(c + bias) when `bias` is given (not with `accumulate`); a has at
// most 256 rows.
void onednn_bf16_rows_one_thread(const ConstMatrixRef& a, const Bf16Weights& b, MatrixRef c,
                                 bool accumulate, const float* bias, Activation activation);

// c (+)= aᵀ·op_b(b), a sum over a's rows (a weight gradient's block of rows).
void onednn_bf16_sum_one_thread(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b,
                                MatrixRef c, bool accumulate);

// oneDNN's implementation of the full blocks' primitive on this processor, e.g. "brg:avx512_core"
// (brgemm kernels) or "gemm:jit" (its sgemm inside: gemm() then calls sgemm itself); for bf16
// operands e.g. "brg:avx512_core_bf16".
std::string onednn_block_kernel(GemmPrecision precision = GemmPrecision::kF32);

}  // namespace fignet::detail
