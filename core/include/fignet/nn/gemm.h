// The network's matrix products, C = op(A)·op(B) or C += op(A)·op(B), on row-major float matrices
// (column blocks of wider ones included). Every product of the forward and backward passes goes
// through gemm(), so the engine that runs them is chosen in one place:
//   - oneDNN (builds with FIGNET_WITH_ONEDNN, the default where libdnnl-dev is found): its kernels
//     are compiled at run time for the processor's instruction set (AVX2, AVX-512, ...);
//   - Eigen: compiled for the build's target (x86-64-v3, or baseline x86-64 in the portable
//     preset); the fallback of a build without oneDNN.
// Both use the threads Eigen::nbThreads() gives (Eigen::setNbThreads, OpenMP's default otherwise)
// and run single-threaded inside an OpenMP parallel region. Results of one engine depend on the
// shape and the processor, not on the thread count: neither engine's own threading promises that
// (oneDNN's avx2 kernels change the last bits with it), so gemm() does the threading itself. Row
// products are cut into fixed blocks of rows, each a one-thread product; the sums over a batch's
// rows (op_a = kYes) into fixed blocks whose one-thread partials are added in block order.
// On oneDNN the row products' full blocks run through its matmul primitive, compiled per shape
// (brgemm kernels where the processor has them), with a Linear layer's bias and ReLU fused in.
#pragma once

#include <string>

#include "fignet/nn/buffer.h"

namespace fignet {

enum class GemmEngine { kEigen, kOneDnn };
enum class Transpose { kNo, kYes };
enum class Activation { kNone, kRelu };

// c = op_a(a)·op_b(b), or c += op_a(a)·op_b(b) when `accumulate`. Shapes must agree (checked in
// debug builds); an empty inner dimension gives zeros (or leaves c unchanged when accumulating).
void gemm(const ConstMatrixRef& a, Transpose op_a, const ConstMatrixRef& b, Transpose op_b,
          MatrixRef c, bool accumulate);

// c = act(a·op_b(b) + bias), a Linear layer's forward product: `bias` is a row of c.cols()
// floats added to every row. On oneDNN the bias and ReLU run inside the product's kernel; on
// Eigen, as one pass over c after it (bias_activation). Same threading and bits as gemm().
void gemm_bias(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b, const float* bias,
               Activation activation, MatrixRef c);

// A row-wise pass fused into a product's blocks of rows: run(context, first, rows) with the
// block's first row and row count, on the thread that computes the block, while its rows are in
// cache. A prologue runs before the block's product (it may write the rows of a the block reads),
// an epilogue after it (and after the bias and activation). Rows are independent, so a pass
// gives the same bits as a loop over all rows before or after the product, for any thread count.
struct RowPass {
  void (*run)(const void* context, Eigen::Index first, Eigen::Index rows) = nullptr;
  const void* context = nullptr;
  void operator()(Eigen::Index first, Eigen::Index rows) const {
    if (run) run(context, first, rows);
  }
};

// gemm_bias with a prologue and an epilogue over each block of rows (either may be empty).
void gemm_bias(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b, const float* bias,
               Activation activation, MatrixRef c, RowPass prologue, RowPass epilogue);
// out = act(x + bias), row by row; x may be out.
void bias_activation(const ConstMatrixRef& x, const float* bias, Activation activation,
                     MatrixRef out);

// The engine gemm() uses: oneDNN where the build has it, unless the environment variable
// FIGNET_GEMM=eigen (read once, at the first product) or set_gemm_engine() chose Eigen.
GemmEngine gemm_engine();
// Process-wide; throws ConfigError when the build lacks the engine, or for Eigen while bf16
// products are on (they run only on oneDNN; set the precision back to kF32 first).
void set_gemm_engine(GemmEngine engine);
bool gemm_engine_available(GemmEngine engine);
// The precision of the products' operands, process-wide like the engine. kF32 by default.
// kBf16 rounds both operands of every product to bfloat16 (8 significant bits, ~0.4 % relative
// error in each operand) and sums in float32: on a processor with bf16 instructions (AVX512-BF16
// or AMX), oneDNN's bf16 kernels run the network's product shapes ~1.3-1.6x as fast as its f32
// ones (docs/network.md). Only on oneDNN; results still do not depend on the thread count.
enum class GemmPrecision { kF32, kBf16 };
GemmPrecision gemm_precision();
// Throws ConfigError saying why where the build, engine or processor cannot run `precision`.
void set_gemm_precision(GemmPrecision precision);
// Why `precision` cannot run here, or "" where it can.
std::string gemm_precision_unavailable(GemmPrecision precision);

// "oneDNN" or "Eigen".
const char* gemm_engine_name(GemmEngine engine);
// What runs the products, for `fignet info` and benchmark reports, e.g. "oneDNN 2.6.3, kernels
// for avx512_core_bf16 (chosen at run time); full row blocks on its matmul primitive
// (brg:avx512_core, bias and ReLU fused)" or "Eigen 3.4.0, AVX SSE2 ... (fixed at compile
// time)".
std::string gemm_description();

}  // namespace fignet
