#include "fignet/nn/gemm.h"

#include <omp.h>

#include <atomic>
#include <cstdlib>
#include <cstring>

#include "fignet/error.h"

#ifdef FIGNET_WITH_ONEDNN
#include <oneapi/dnnl/dnnl.h>
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

#ifdef FIGNET_WITH_ONEDNN
void onednn_gemm(const ConstMatrixRef& a, Transpose op_a, const ConstMatrixRef& b, Transpose op_b,
                 MatrixRef c, bool accumulate) {
  const Eigen::Index m = c.rows(), n = c.cols();
  const Eigen::Index k = op_a == Transpose::kNo ? a.cols() : a.rows();
  // oneDNN's OpenMP runtime takes omp_get_max_threads(); follow Eigen's setting, as Eigen would.
  // Except for aᵀ·b (weight gradients: sums over the rows of a batch), which oneDNN may split
  // along that sum between threads: one thread keeps the sum's order, and the gradients, the same
  // for any thread count.
  const int threads = op_a == Transpose::kYes ? 1 : Eigen::nbThreads();
  const int before = omp_get_max_threads();
  if (threads != before) omp_set_num_threads(threads);
  // Row-major throughout: oneDNN's sgemm takes row-major operands and leading dimensions.
  const dnnl_status_t status =
      dnnl_sgemm(op_a == Transpose::kNo ? 'N' : 'T', op_b == Transpose::kNo ? 'N' : 'T', m, n, k,
                 1.0f, a.data(), a.outerStride(), b.data(), b.outerStride(),
                 accumulate ? 1.0f : 0.0f, c.data(), c.outerStride());
  if (threads != before) omp_set_num_threads(before);
  if (status != dnnl_success) {
    throw Error("gemm: oneDNN's sgemm failed (status " + std::to_string(status) + ") on " +
                std::to_string(m) + "x" + std::to_string(k) + " times " + std::to_string(k) + "x" +
                std::to_string(n));
  }
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
#ifdef FIGNET_WITH_ONEDNN
  if (current_engine().load(std::memory_order_relaxed) == GemmEngine::kOneDnn) {
    onednn_gemm(a, op_a, b, op_b, c, accumulate);
    return;
  }
#endif
  eigen_gemm(a, op_a, b, op_b, c, accumulate);
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
         " (chosen at run time)";
#else
  return "Eigen";
#endif
}

}  // namespace fignet
