#include "fignet/nn/gemm.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>

#include "fignet/error.h"
#include "fignet/nn/gemm_log.h"
#include "parallel/parallel_for.h"

#ifdef FIGNET_WITH_ONEDNN
#include <oneapi/dnnl/dnnl.h>

#include "nn/onednn_matmul.h"
#endif

namespace fignet {

namespace {

constexpr GemmEngine kBuildDefault =
#ifdef FIGNET_WITH_ONEDNN
    GemmEngine::kOneDnn;
#else
    GemmEngine::kEigen;
#endif

// The environment decides once; set_gemm_engine() overrides it.
GemmEngine engine_from_environment() {
  const char* choice = std::getenv("FIGNET_GEMM");
  if (choice && std::strcmp(choice, "eigen") == 0) return GemmEngine::kEigen;
  return kBuildDefault;
}

std::atomic<GemmEngine>& current_engine() {
  static std::atomic<GemmEngine> engine(engine_from_environment());
  return engine;
}

std::atomic<GemmPrecision>& current_precision() {
  static std::atomic<GemmPrecision> precision(GemmPrecision::kF32);
  return precision;
}

#ifdef FIGNET_WITH_ONEDNN
// Whether this product runs in bf16: only on oneDNN (GemmPrecision's contract).
bool bf16_products(GemmEngine engine) {
  return engine == GemmEngine::kOneDnn &&
         current_precision().load(std::memory_order_relaxed) == GemmPrecision::kBf16;
}
#endif

void eigen_gemm(const ConstMatrixRef& a, Transpose op_a, const ConstMatrixRef& b, Transpose op_b,
                MatrixRef c, bool accumulate) {
  auto assign = [&](const auto& lhs, const auto& rhs) {
    if (accumulate) {
      c.noalias() += lhs * rhs;
    } else {
      c.noalias() = lhs * rhs;
    }
  };
  const bool ta = op_a == Transpose::kYes, tb = op_b == Transpose::kYes;
  if (!ta && !tb) assign(a, b);
  if (!ta && tb) assign(a, b.transpose());
  if (ta && !tb) assign(a.transpose(), b);
  if (ta && tb) assign(a.transpose(), b.transpose());
}

// eigen_gemm on the calling thread alone: Eigen threads a product unless Eigen::nbThreads() is 1
// or it runs inside an OpenMP team of several threads, so it gets such a team with one worker.
void eigen_gemm_one_thread(const ConstMatrixRef& a, Transpose op_a, const ConstMatrixRef& b,
                           Transpose op_b, MatrixRef c, bool accumulate) {
  if (Eigen::nbThreads() == 1 || omp_get_num_threads() > 1) {
    eigen_gemm(a, op_a, b, op_b, c, accumulate);
    return;
  }
#pragma omp parallel num_threads(2)
#pragma omp single
  eigen_gemm(a, op_a, b, op_b, c, accumulate);
}

#ifdef FIGNET_WITH_ONEDNN
// oneDNN's sgemm on the calling thread alone; returns its status.
dnnl_status_t onednn_gemm_one_thread(const ConstMatrixRef& a, Transpose op_a,
                                     const ConstMatrixRef& b, Transpose op_b, MatrixRef c,
                                     bool accumulate) {
  const Eigen::Index m = c.rows(), n = c.cols();
  const Eigen::Index k = op_a == Transpose::kNo ? a.cols() : a.rows();
  const detail::OneOmpThread one_thread;
  // Row-major throughout: oneDNN's sgemm takes row-major operands and leading dimensions.
  return dnnl_sgemm(op_a == Transpose::kNo ? 'N' : 'T', op_b == Transpose::kNo ? 'N' : 'T', m, n, k,
                    1.0f, a.data(), a.outerStride(), b.data(), b.outerStride(),
                    accumulate ? 1.0f : 0.0f, c.data(), c.outerStride());
}

void check_onednn(dnnl_status_t status, Eigen::Index m, Eigen::Index k, Eigen::Index n) {
  if (status != dnnl_success) {
    throw Error("gemm: oneDNN's sgemm failed (status " + std::to_string(status) + ") on " +
                std::to_string(m) + "x" + std::to_string(k) + " times " + std::to_string(k) + "x" +
                std::to_string(n));
  }
}
#endif

// Threads that share the blocks of a product: Eigen's setting, or one inside an OpenMP team
// (whose products are single-threaded already).
int threads_for_blocks() {
  return omp_in_parallel() ? 1 : Eigen::nbThreads();
}

// The engine's product on the calling thread alone.
void gemm_one_thread(GemmEngine engine, const ConstMatrixRef& a, Transpose op_a,
                     const ConstMatrixRef& b, Transpose op_b, MatrixRef c, bool accumulate) {
#ifdef FIGNET_WITH_ONEDNN
  if (engine == GemmEngine::kOneDnn) {
    check_onednn(onednn_gemm_one_thread(a, op_a, b, op_b, c, accumulate), c.rows(),
                 op_a == Transpose::kNo ? a.cols() : a.rows(), c.cols());
    return;
  }
#endif
  (void)engine;
  eigen_gemm_one_thread(a, op_a, b, op_b, c, accumulate);
}

// A weight gradient's block, c (+)= aᵀ·op_b(b): the engine's product on the calling thread
// alone, in bf16 where chosen.
void sum_one_thread(GemmEngine engine, const ConstMatrixRef& a, const ConstMatrixRef& b,
                    Transpose op_b, MatrixRef c, bool accumulate) {
#ifdef FIGNET_WITH_ONEDNN
  if (bf16_products(engine)) {
    detail::onednn_bf16_sum_one_thread(a, b, op_b, c, accumulate);
    return;
  }
#endif
  gemm_one_thread(engine, a, Transpose::kYes, b, op_b, c, accumulate);
}

// Rows of a block of a weight gradient's sum (below). 512 cost 2-4 % of a one-thread training
// step in partials and short products and gained 3 % on two threads; 2048 measured the same as
// one product per sum on both (bench_network, 2026-11-23): the threads share the sums of a batch's
// chunk-sized graphs, not of one scene's.
constexpr Eigen::Index kSumBlockRows = 2048;

// c (+)= aᵀ·op_b(b): the weight gradients, sums over a batch's rows. Both engines would split
// that sum between threads in a way that depends on their number, and so would the gradients'
// last bits. Instead the rows are cut into blocks of kSumBlockRows; each block's product runs on
// one thread into a partial of its own, and the partials are added to c in block order: the same
// sums in the same order for any thread count, with the blocks shared among the threads.
void weight_gradient(GemmEngine engine, const ConstMatrixRef& a, const ConstMatrixRef& b,
                     Transpose op_b, MatrixRef c, bool accumulate) {
  const Eigen::Index m = c.rows(), n = c.cols(), k = a.rows();
  const Eigen::Index blocks = (k + kSumBlockRows - 1) / kSumBlockRows;
  if (blocks == 1) {
    sum_one_thread(engine, a, b, op_b, c, accumulate);
    return;
  }
  // The partials persist per thread, so a steady-state step does not allocate.
  thread_local AlignedFloats partials;
  const size_t partial_size = static_cast<size_t>(m * n);
  if (partials.size() < partial_size * blocks) partials.resize(partial_size * blocks);
  float* const partial = partials.data();
  auto run_block = [&](Eigen::Index block) {
    const Eigen::Index first = block * kSumBlockRows;
    const Eigen::Index rows = std::min(kSumBlockRows, k - first);
    MatrixView out(partial + block * partial_size, m, n);
    const ConstMatrixRef b_block = op_b == Transpose::kNo
                                       ? ConstMatrixRef(b.middleRows(first, rows))
                                       : ConstMatrixRef(b.middleCols(first, rows));
    sum_one_thread(engine, a.middleRows(first, rows), b_block, op_b, out, false);
  };
  detail::parallel_for(static_cast<int>(blocks), threads_for_blocks(),
                       detail::Schedule::kContiguous, run_block);
  // c = (c or 0) + partial_0 + partial_1 + ..., in that order for every element.
  for (Eigen::Index r = 0; r < m; ++r) {
    float* row = c.row(r).data();
    if (!accumulate) std::fill(row, row + n, 0.0f);
    for (Eigen::Index block = 0; block < blocks; ++block) {
      const float* in = partial + block * partial_size + r * n;
      for (Eigen::Index j = 0; j < n; ++j) row[j] += in[j];
    }
  }
}

// Rows of a block of a row product (below): enough for a one-thread product at full speed, few
// enough that a scene's graph of a few thousand rows still shares out among threads. On oneDNN
// the full blocks run on matmul primitives compiled for this row count.
constexpr Eigen::Index kProductBlockRows = 256;

// c (+)= a·op_b(b), then c = act(c + bias) when `bias` is given; each row of c a product of its
// own. A threaded sgemm splits the work in a way that depends on the thread count, and on some
// kernels (oneDNN's avx2 ones) so do the rows' last bits. Instead the rows are cut into blocks of
// kProductBlockRows, each block a one-thread product, and the blocks shared among the threads: a
// row's bits depend only on its block, never on the thread count.
// The row passes around each block run on the block's thread (gemm_bias with RowPass).
void row_products(GemmEngine engine, const ConstMatrixRef& a, const ConstMatrixRef& b,
                  Transpose op_b, MatrixRef c, bool accumulate, const float* bias,
                  Activation activation, RowPass prologue = {}, RowPass epilogue = {}) {
  const Eigen::Index m = c.rows();
  const Eigen::Index blocks = (m + kProductBlockRows - 1) / kProductBlockRows;
#ifdef FIGNET_WITH_ONEDNN
  // In bf16, b is rounded once for all blocks, by the calling thread (whose scratch the blocks'
  // threads then only read).
  const bool bf16 = bf16_products(engine);
  detail::Bf16Weights b_bf16;
  if (bf16) {
    thread_local detail::AlignedBf16 weights;
    if (weights.size() < static_cast<size_t>(b.size())) weights.resize(b.size());
    detail::copy_to_bf16(b, b.rows(), b.cols(), weights.data());
    b_bf16 = {weights.data(), a.cols(), c.cols(), op_b};
  }
#endif
  auto run_block = [&](int block) {
    const Eigen::Index first = block * kProductBlockRows;
    const Eigen::Index rows = std::min(kProductBlockRows, m - first);
    prologue(first, rows);
    const ConstMatrixRef a_rows = a.middleRows(first, rows);
    MatrixRef c_rows = c.middleRows(first, rows);
#ifdef FIGNET_WITH_ONEDNN
    if (bf16) {
      detail::onednn_bf16_rows_one_thread(a_rows, b_bf16, c_rows, accumulate, bias, activation);
      epilogue(first, rows);
      return;
    }
    if (engine == GemmEngine::kOneDnn && rows == kProductBlockRows &&
        detail::onednn_matmul_one_thread(a_rows, b, op_b, c_rows, accumulate, bias, activation)) {
      epilogue(first, rows);
      return;
    }
#endif
    gemm_one_thread(engine, a_rows, Transpose::kNo, b, op_b, c_rows, accumulate);
    if (bias) bias_activation(c_rows, bias, activation, c_rows);
    epilogue(first, rows);
  };
  detail::parallel_for(static_cast<int>(blocks), threads_for_blocks(),
                       detail::Schedule::kContiguous, run_block);
}

#ifdef FIGNET_WITH_ONEDNN
// Which oneDNN implementation runs the full blocks of row products here.
std::string block_products_description() {
  const std::string kernel = detail::onednn_block_kernel();
  if (kernel.starts_with("brg")) {
    return "full row blocks on its matmul primitive (" + kernel + ", bias and ReLU fused)";
  }
  return "every product on its sgemm (no brgemm matmul kernel for this processor)";
}

const char* isa_name(dnnl_cpu_isa_t isa) {
  switch (isa) {
    case dnnl_cpu_isa_sse41:
      return "sse41";
    case dnnl_cpu_isa_avx:
      return "avx";
    case dnnl_cpu_isa_avx2:
      return "avx2";
    case dnnl_cpu_isa_avx2_vnni:
      return "avx2_vnni";
    case dnnl_cpu_isa_avx512_core:
      return "avx512_core";
    case dnnl_cpu_isa_avx512_core_vnni:
      return "avx512_core_vnni";
    case dnnl_cpu_isa_avx512_core_bf16:
      return "avx512_core_bf16";
    case dnnl_cpu_isa_avx512_core_amx:
      return "avx512_core_amx";
    default:
      return "another instruction set";
  }
}
#endif

}  // namespace

void gemm(const ConstMatrixRef& a, Transpose op_a, const ConstMatrixRef& b, Transpose op_b,
          MatrixRef c, bool accumulate) {
  const Eigen::Index k = op_a == Transpose::kNo ? a.cols() : a.rows();
  eigen_assert(c.rows() == (op_a == Transpose::kNo ? a.rows() : a.cols()));
  eigen_assert(c.cols() == (op_b == Transpose::kNo ? b.cols() : b.rows()));
  eigen_assert(k == (op_b == Transpose::kNo ? b.rows() : b.cols()));
  if (c.rows() == 0 || c.cols() == 0) return;
  if (k == 0) {
    if (!accumulate) c.setZero();
    return;
  }
  const detail::LoggedProduct logged(
      {c.rows(), k, c.cols(), op_a, op_b, accumulate, false, Activation::kNone});
  const GemmEngine engine = current_engine().load(std::memory_order_relaxed);
  if (op_a == Transpose::kYes) {
    weight_gradient(engine, a, b, op_b, c, accumulate);
    return;
  }
  row_products(engine, a, b, op_b, c, accumulate, nullptr, Activation::kNone);
}

void gemm_bias(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b, const float* bias,
               Activation activation, MatrixRef c) {
  gemm_bias(a, b, op_b, bias, activation, c, {}, {});
}

void gemm_bias(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b, const float* bias,
               Activation activation, MatrixRef c, RowPass prologue, RowPass epilogue) {
  const Eigen::Index k = a.cols();
  eigen_assert(c.rows() == a.rows());
  eigen_assert(c.cols() == (op_b == Transpose::kNo ? b.cols() : b.rows()));
  eigen_assert(k == (op_b == Transpose::kNo ? b.rows() : b.cols()));
  if (c.rows() == 0 || c.cols() == 0) return;
  if (k == 0) {
    prologue(0, c.rows());
    c.setZero();
    bias_activation(c, bias, activation, c);
    epilogue(0, c.rows());
    return;
  }
  const detail::LoggedProduct logged(
      {c.rows(), k, c.cols(), Transpose::kNo, op_b, false, true, activation},
      prologue.run != nullptr || epilogue.run != nullptr);
  row_products(current_engine().load(std::memory_order_relaxed), a, b, op_b, c, false, bias,
               activation, prologue, epilogue);
}

// The elementwise passes walk each row once while it is in L1, with plain loops over contiguous
// columns that the compiler vectorises (Eigen's row-wise expressions on row-major matrices
// re-read rows).
void bias_activation(const ConstMatrixRef& x, const float* bias, Activation activation,
                     MatrixRef out) {
  const Eigen::Index cols = x.cols();
  for (Eigen::Index r = 0; r < x.rows(); ++r) {
    const float* in = x.row(r).data();
    float* row = out.row(r).data();
    if (activation == Activation::kRelu) {
      for (Eigen::Index j = 0; j < cols; ++j) row[j] = std::max(in[j] + bias[j], 0.0f);
    } else {
      for (Eigen::Index j = 0; j < cols; ++j) row[j] = in[j] + bias[j];
    }
  }
}

GemmPrecision gemm_precision() {
  return current_precision().load();
}

std::string gemm_precision_unavailable(GemmPrecision precision) {
  if (precision == GemmPrecision::kF32) return {};
  if (gemm_engine() == GemmEngine::kEigen) {
    return "the products run on Eigen (FIGNET_GEMM=eigen or set_gemm_engine), bf16 needs oneDNN";
  }
#ifdef FIGNET_WITH_ONEDNN
  if (!detail::onednn_bf16_available()) {
    return std::string("oneDNN runs ") + isa_name(dnnl_get_effective_cpu_isa()) +
           " kernels here, without bf16 instructions (they need AVX512-BF16 or AMX: Intel Cooper "
           "Lake, Sapphire Rapids or newer, AMD Zen 4 or newer; or ONEDNN_MAX_CPU_ISA caps them)";
  }
  return {};
#else
  return "this build has no oneDNN (configure with FIGNET_WITH_ONEDNN=ON and libdnnl-dev "
         "installed)";
#endif
}

void set_gemm_precision(GemmPrecision precision) {
  const std::string why_not = gemm_precision_unavailable(precision);
  if (!why_not.empty()) {
    throw ConfigError("bf16 products: " + why_not);
  }
  current_precision().store(precision);
}

GemmEngine gemm_engine() {
  return current_engine().load();
}

bool gemm_engine_available(GemmEngine engine) {
#ifdef FIGNET_WITH_ONEDNN
  (void)engine;
  return true;
#else
  return engine == GemmEngine::kEigen;
#endif
}

void set_gemm_engine(GemmEngine engine) {
  if (!gemm_engine_available(engine)) {
    throw ConfigError(std::string("set_gemm_engine: this build has no ") +
                      gemm_engine_name(engine) +
                      " (configure with FIGNET_WITH_ONEDNN=ON and libdnnl-dev installed)");
  }
  // bf16 products run only on oneDNN: switching them to Eigen would make them f32 unasked.
  if (engine == GemmEngine::kEigen && gemm_precision() == GemmPrecision::kBf16) {
    throw ConfigError(
        "set_gemm_engine: bf16 products are on and run only on oneDNN; "
        "set_gemm_precision(GemmPrecision::kF32) before switching to Eigen");
  }
  current_engine().store(engine);
}

const char* gemm_engine_name(GemmEngine engine) {
  return engine == GemmEngine::kOneDnn ? "oneDNN" : "Eigen";
}

std::string gemm_description() {
  if (gemm_engine() == GemmEngine::kEigen) {
    return "Eigen " + std::to_string(EIGEN_WORLD_VERSION) + "." +
           std::to_string(EIGEN_MAJOR_VERSION) + "." + std::to_string(EIGEN_MINOR_VERSION) + ", " +
           Eigen::SimdInstructionSetsInUse() + " (fixed at compile time)";
  }
#ifdef FIGNET_WITH_ONEDNN
  const dnnl_version_t* v = dnnl_version();
  return "oneDNN " + std::to_string(v->major) + "." + std::to_string(v->minor) + "." +
         std::to_string(v->patch) + ", kernels for " + isa_name(dnnl_get_effective_cpu_isa()) +
         " (chosen at run time); " +
         (gemm_precision() == GemmPrecision::kBf16
              ? std::string("every product in bf16 (operands rounded to bfloat16, sums in f32) "
                            "on its matmul primitive (") +
                    detail::onednn_block_kernel(GemmPrecision::kBf16) + ")"
              : block_products_description());
#else
  return "Eigen";
#endif
}

}  // namespace fignet
