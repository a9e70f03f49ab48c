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
  bool operator==(const MatmulKey&) const = default;
};

struct MatmulKeyHash {
  size_t operator()(const MatmulKey& key) const {
    size_t h = 0;
    for (Eigen::Index v : {key.m, key.k, key.n, key.lda, key.ldb, key.ldc}) {
      h = h * 1000003u ^ static_cast<size_t>(v);
    }
    return h * 31u + (key.transpose_b << 3 | key.accumulate << 2 | key.bias << 1 | key.relu);
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
                            bool transposed) {
  using dims = dnnl::memory::dims;
  return {dims{rows, cols}, dnnl::memory::data_type::f32,
          transposed ? dims{1, row_stride} : dims{row_stride, 1}};
}

CompiledMatmul compile(const MatmulKey& key) {
  const dnnl::engine& engine = cpu_engine();
  const dnnl::memory::desc src = describe(key.m, key.k, key.lda, false);
  const dnnl::memory::desc weights = describe(key.k, key.n, key.ldb, key.transpose_b);
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

std::string onednn_block_kernel() {
  const OneOmpThread one_thread;
  const dnnl::memory::desc block = describe(256, 64, 64, false);
  const dnnl::memory::desc weights = describe(64, 64, 64, false);
  return dnnl::matmul::primitive_desc(dnnl::matmul::desc(block, weights, block), cpu_engine())
      .impl_info_str();
}

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
  // Per thread: primitives and memory objects are mutated per call (data handles), and each
  // thread's stream is its own.
  thread_local std::unordered_map<MatmulKey, CompiledMatmul, MatmulKeyHash> compiled_by_key;
  thread_local dnnl::stream stream(cpu_engine());
  const OneOmpThread one_thread;
  try {
    auto found = compiled_by_key.find(key);
    if (found == compiled_by_key.end()) found = compiled_by_key.emplace(key, compile(key)).first;
    CompiledMatmul& matmul = found->second;
    if (!matmul.brgemm) return false;
    matmul.src.set_data_handle(const_cast<float*>(a.data()));
    matmul.weights.set_data_handle(const_cast<float*>(b.data()));
    matmul.dst.set_data_handle(c.data());
    if (bias) matmul.bias.set_data_handle(const_cast<float*>(bias));
    matmul.primitive.execute(stream, matmul.arguments);
  } catch (const dnnl::error& e) {
    throw Error("gemm: oneDNN's matmul failed (" + std::string(e.what()) + ", status " +
                std::to_string(e.status) + ") on " + std::to_string(key.m) + "x" +
                std::to_string(key.k) + " times " + std::to_string(key.k) + "x" +
                std::to_string(key.n));
  }
  return true;
}

}  // namespace fignet::detail
