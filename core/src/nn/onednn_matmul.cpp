#include "nn/onednn_matmul.h"

#include <oneapi/dnnl/dnnl.hpp>
#include <string>
#include <unordered_map>

#include "fignet/error.h"

namespace fignet::detail {

namespace {

// What a compiled primitive is specific to.
struct MatmulKey {
  Eigen::Index m, k, n, lda, ldb, ldc;
  bool transpose_b, accumulate, bias, relu;
  bool transpose_a = false, bf16 = false;
  bool operator==(const MatmulKey&) const = default;
};

struct MatmulKeyHash {
  size_t operator()(const MatmulKey& key) const {
    size_t h = 0;
    for (Eigen::Index v : {key.m, key.k, key.n, key.lda, key.ldb, key.ldc}) {
      h = h * 1000003u ^ static_cast<size_t>(v);
    }
    return h * 127u + (key.bf16 << 5 | key.transpose_a << 4 | key.transpose_b << 3 |
                       key.accumulate << 2 | key.bias << 1 | key.relu);
  }
};

// A primitive with its operands' memory objects, whose data handles are set per call, and the
// argument map that names them (built once: execute() takes it by reference).
struct CompiledMatmul {
  // oneDNN's brgemm kernels, made for the shape. Elsewhere (processors without AVX-512 in oneDNN
  // 2.6) the primitive wraps the same sgemm that gemm() calls, so gemm() calls it directly.
  bool brgemm = false;
  dnnl::matmul primitive;
  dnnl::memory src, weights, bias, dst;
  std::unordered_map<int, dnnl::memory> arguments;
};

const dnnl::engine& cpu_engine() {
  static const dnnl::engine engine(dnnl::engine::kind::cpu, 0);
  return engine;
}

// Row-major operands as oneDNN memory descriptors: shape and strides (column blocks of wider
// matrices have a row stride above their width; a transposed operand swaps the strides).
dnnl::memory::desc describe(Eigen::Index rows, Eigen::Index cols, Eigen::Index row_stride,
                            bool transposed,
                            dnnl::memory::data_type type = dnnl::memory::data_type::f32) {
  using dims = dnnl::memory::dims;
  return {dims{rows, cols}, type, transposed ? dims{1, row_stride} : dims{row_stride, 1}};
}

CompiledMatmul compile(const MatmulKey& key) {
  const dnnl::engine& engine = cpu_engine();
  // bf16 operands, f32 results: oneDNN sums the products in f32.
  const auto operand_type = key.bf16 ? dnnl::memory::data_type::bf16 : dnnl::memory::data_type::f32;
  const dnnl::memory::desc src = describe(key.m, key.k, key.lda, key.transpose_a, operand_type);
  const dnnl::memory::desc weights = describe(key.k, key.n, key.ldb, key.transpose_b, operand_type);
  const dnnl::memory::desc dst = describe(key.m, key.n, key.ldc, false);
  const dnnl::memory::desc bias =
      key.bias ? describe(1, key.n, key.n, false) : dnnl::memory::desc();
  dnnl::post_ops post_ops;
  if (key.accumulate) post_ops.append_sum(1.0f);
  if (key.relu) post_ops.append_eltwise(1.0f, dnnl::algorithm::eltwise_relu, 0.0f, 0.0f);
  dnnl::primitive_attr attributes;
  attributes.set_post_ops(post_ops);
  const dnnl::matmul::primitive_desc description(key.bias
                                                     ? dnnl::matmul::desc(src, weights, bias, dst)
                                                     : dnnl::matmul::desc(src, weights, dst),
                                                 attributes, engine);
  CompiledMatmul compiled{std::string(description.impl_info_str()).starts_with("brg"),
                          dnnl::matmul(description),
                          dnnl::memory(src, engine, DNNL_MEMORY_NONE),
                          dnnl::memory(weights, engine, DNNL_MEMORY_NONE),
                          {},
                          dnnl::memory(dst, engine, DNNL_MEMORY_NONE),
                          {}};
  compiled.arguments = {{DNNL_ARG_SRC, compiled.src},
                        {DNNL_ARG_WEIGHTS, compiled.weights},
                        {DNNL_ARG_DST, compiled.dst}};
  if (key.bias) {
    compiled.bias = dnnl::memory(bias, engine, DNNL_MEMORY_NONE);
    compiled.arguments.emplace(DNNL_ARG_BIAS, compiled.bias);
  }
  return compiled;
}

}  // namespace

std::string onednn_block_kernel(GemmPrecision precision) {
  const OneOmpThread one_thread;
  const auto operands = precision == GemmPrecision::kBf16 ? dnnl::memory::data_type::bf16
                                                          : dnnl::memory::data_type::f32;
  const dnnl::memory::desc block = describe(256, 64, 64, false, operands);
  const dnnl::memory::desc weights = describe(64, 64, 64, false, operands);
  const dnnl::memory::desc result = describe(256, 64, 64, false);
  return dnnl::matmul::primitive_desc(dnnl::matmul::desc(block, weights, result), cpu_engine())
      .impl_info_str();
}

namespace {

// The primitive for `key`, compiled on this thread at its first use. Per thread: primitives and
// memory objects are mutated per call (data handles).
CompiledMatmul& compiled_for(const MatmulKey& key) {
  thread_local std::unordered_map<MatmulKey, CompiledMatmul, MatmulKeyHash> compiled_by_key;
  auto found = compiled_by_key.find(key);
  if (found == compiled_by_key.end()) found = compiled_by_key.emplace(key, compile(key)).first;
  return found->second;
}

// Runs the primitive for `key` on the operands at these addresses, on this thread's stream. With
// `brgemm_only`, runs nothing and returns false where its kernel is not brgemm.
bool run_matmul(const MatmulKey& key, const void* a, const void* b, float* c, const float* bias,
                bool brgemm_only) {
  thread_local dnnl::stream stream(cpu_engine());
  const OneOmpThread one_thread;
  try {
    CompiledMatmul& matmul = compiled_for(key);
    if (brgemm_only && !matmul.brgemm) return false;
    matmul.src.set_data_handle(const_cast<void*>(a));
    matmul.weights.set_data_handle(const_cast<void*>(b));
    matmul.dst.set_data_handle(c);
    if (bias) matmul.bias.set_data_handle(const_cast<float*>(bias));
    matmul.primitive.execute(stream, matmul.arguments);
  } catch (const dnnl::error& e) {
    throw Error("gemm: oneDNN's " + std::string(key.bf16 ? "bf16 " : "") + "matmul failed (" +
                std::string(e.what()) + ", status " + std::to_string(e.status) + ") on " +
                std::to_string(key.m) + "x" + std::to_string(key.k) + " times " +
                std::to_string(key.k) + "x" + std::to_string(key.n));
  }
  return true;
}

Eigen::Index round_up(Eigen::Index n, Eigen::Index quantum) {
  return (n + quantum - 1) / quantum * quantum;
}

}  // namespace

bool onednn_matmul_one_thread(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b,
                              MatrixRef c, bool accumulate, const float* bias,
                              Activation activation) {
  eigen_assert(!(accumulate && bias));
  const MatmulKey key{c.rows(),
                      a.cols(),
                      c.cols(),
                      a.outerStride(),
                      b.outerStride(),
                      c.outerStride(),
                      op_b == Transpose::kYes,
                      accumulate,
                      bias != nullptr,
                      bias != nullptr && activation == Activation::kRelu};
  return run_matmul(key, a.data(), b.data(), c.data(), bias, /*brgemm_only=*/true);
}

bool onednn_bf16_available() {
  // The ISA oneDNN dispatches to, which DNNL_MAX_CPU_ISA may cap below the processor's.
  const dnnl_cpu_isa_t isa = dnnl_get_effective_cpu_isa();
  return (isa & dnnl_cpu_isa_avx512_core_bf16) == dnnl_cpu_isa_avx512_core_bf16;
}

void onednn_bf16_rows_one_thread(const ConstMatrixRef& a, const Bf16Weights& b, MatrixRef c,
                                 bool accumulate, const float* bias, Activation activation) {
  eigen_assert(!(accumulate && bias));
  eigen_assert(a.cols() == b.k && c.cols() == b.n && a.rows() == c.rows());
  const Eigen::Index rows = c.rows(), k = b.k, n = b.n;
  const Eigen::Index padded = round_up(rows, kBf16RowQuantum);
  thread_local AlignedBf16 a_bf16;
  if (a_bf16.size() < static_cast<size_t>(padded * k)) a_bf16.resize(padded * k);
  copy_to_bf16(a, padded, k, a_bf16.data());
  const bool relu = bias != nullptr && activation == Activation::kRelu;
  const Eigen::Index ldb = b.op == Transpose::kNo ? n : k;
  // Straight into c where no rows were padded and a brgemm kernel takes c's row stride.
  MatmulKey key{
      padded,          k,    n,     k,   ldb, c.outerStride(), b.op == Transpose::kYes, accumulate,
      bias != nullptr, relu, false, true};
  if (padded == rows && run_matmul(key, a_bf16.data(), b.data, c.data(), bias, true)) return;
  // Otherwise into a dense scratch, then its first rows into c.
  thread_local AlignedFloats scratch;
  if (scratch.size() < static_cast<size_t>(padded * n)) scratch.resize(padded * n);
  key.ldc = n;
  key.accumulate = false;
  run_matmul(key, a_bf16.data(), b.data, scratch.data(), bias, false);
  const ConstMatrixView result(scratch.data(), padded, n);
  if (accumulate) {
    c += result.topRows(rows);
  } else {
    c = result.topRows(rows);
  }
}

void onednn_bf16_sum_one_thread(const ConstMatrixRef& a, const ConstMatrixRef& b, Transpose op_b,
                                MatrixRef c, bool accumulate) {
  const Eigen::Index sum = a.rows(), m = a.cols(), n = c.cols();
  eigen_assert(c.rows() == m && (op_b == Transpose::kNo ? b.rows() : b.cols()) == sum);
  const Eigen::Index padded = round_up(sum, kBf16SumQuantum);
  // a as stored (sum x m) is aᵀ transposed: oneDNN reads it with swapped strides. op_b(b) gets
  // zero rows (zero columns of its transposed storage) to the same padded length.
  thread_local AlignedBf16 a_bf16, b_bf16;
  if (a_bf16.size() < static_cast<size_t>(padded * m)) a_bf16.resize(padded * m);
  if (b_bf16.size() < static_cast<size_t>(padded * n)) b_bf16.resize(padded * n);
  copy_to_bf16(a, padded, m, a_bf16.data());
  const bool transpose_b = op_b == Transpose::kYes;
  if (transpose_b) {
    copy_to_bf16(b, n, padded, b_bf16.data());
  } else {
    copy_to_bf16(b, padded, n, b_bf16.data());
  }
  const MatmulKey key{
      m,     padded, n,    m,   transpose_b ? padded : n, c.outerStride(), transpose_b, accumulate,
      false, false,  true, true};
  run_matmul(key, a_bf16.data(), b_bf16.data(), c.data(), nullptr, false);
}

}  // namespace fignet::detail
