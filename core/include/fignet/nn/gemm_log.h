// The products a pass runs, recorded as gemm() and gemm_bias() were asked for them. For
// benchmarks: the FLOPs of the record are the pass's exact count, and the same products run bare
// (same engine, precision and threads, no passes around them) are the ceiling the pass is held to.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <vector>

#include "fignet/nn/gemm.h"

namespace fignet {

// One product: c (m x n) = op_a(a) (m x k) · op_b(b) (k x n), added to c when `accumulate`; with
// `bias`, gemm_bias's Linear layer (bias, then `activation`).
struct GemmShape {
  Eigen::Index m = 0, k = 0, n = 0;
  Transpose op_a = Transpose::kNo, op_b = Transpose::kNo;
  bool accumulate = false;
  bool bias = false;
  Activation activation = Activation::kNone;

  double flops() const { return 2.0 * static_cast<double>(m) * static_cast<double>(k) * n; }
  friend bool operator==(const GemmShape&, const GemmShape&) = default;
};

// Records every product started on any thread while it lives, in the order they started, with
// the seconds it took where it ran (inside a pass: operands as the passes left them in cache);
// products with an empty result or inner dimension do no arithmetic and are left out. One log at
// a time: constructing a second while one lives throws ConfigError.
class GemmLog {
 public:
  GemmLog();
  ~GemmLog();
  GemmLog(const GemmLog&) = delete;
  GemmLog& operator=(const GemmLog&) = delete;

  std::vector<GemmShape> shapes() const;
  double flops() const;
  // Per product, as shapes(): its seconds, and whether they include row passes fused into its
  // blocks (gemm_bias's prologue or epilogue), which the bare product does not run.
  std::vector<double> seconds() const;
  std::vector<bool> with_row_passes() const;

  // Called by gemm() and gemm_bias() for the live log: add() as a product starts (returns its
  // index), finish() as it ends.
  size_t add(const GemmShape& shape, bool row_passes = false);
  void finish(size_t index, double seconds);

 private:
  mutable std::mutex mutex_;
  std::vector<GemmShape> shapes_;
  std::vector<double> seconds_;
  std::vector<bool> row_passes_;
};

// Runs `shapes` bare, each with gemm() or gemm_bias() on fresh packed operands (values in
// [-1, 1]), in order, repeatedly until `min_seconds` have passed; with `share_out` the passes'
// products are shared out among OpenMP's threads, each run on one thread, as a training batch's
// chunks of scenes run. Returns the seconds of one pass over the list; with `each`, also every
// product's mean seconds (as shapes).
double time_gemm_shapes(const std::vector<GemmShape>& shapes, double min_seconds, bool share_out,
                        std::vector<double>* each = nullptr);

namespace detail {
// The live log, or null; read by every product.
extern std::atomic<GemmLog*> live_gemm_log;

// Logs a product to the live log, if any, for as long as it lives (one per gemm() call).
class LoggedProduct {
 public:
  explicit LoggedProduct(const GemmShape& shape, bool row_passes = false)
      : log_(live_gemm_log.load(std::memory_order_relaxed)) {
    if (log_ == nullptr) return;
    index_ = log_->add(shape, row_passes);
    start_ = std::chrono::steady_clock::now();
  }
  ~LoggedProduct() {
    if (log_ == nullptr) return;
    log_->finish(index_,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  }
  LoggedProduct(const LoggedProduct&) = delete;
  LoggedProduct& operator=(const LoggedProduct&) = delete;

 private:
  GemmLog* log_;
  size_t index_ = 0;
  std::chrono::steady_clock::time_point start_;
};
}  // namespace detail

}  // namespace fignet
