#include "fignet/nn/gemm_log.h"

#include <algorithm>
#include <chrono>
#include <numeric>

#include "fignet/error.h"
#include "parallel/parallel_for.h"

namespace fignet {

namespace detail {
std::atomic<GemmLog*> live_gemm_log{nullptr};
}  // namespace detail

GemmLog::GemmLog() {
  GemmLog* none = nullptr;
  if (!detail::live_gemm_log.compare_exchange_strong(none, this)) {
    throw ConfigError("GemmLog: another log is recording the products already");
  }
}

GemmLog::~GemmLog() {
  detail::live_gemm_log.store(nullptr);
}

size_t GemmLog::add(const GemmShape& shape, bool row_passes) {
  const std::lock_guard lock(mutex_);
  shapes_.push_back(shape);
  seconds_.push_back(0.0);
  row_passes_.push_back(row_passes);
  return shapes_.size() - 1;
}

void GemmLog::finish(size_t index, double seconds) {
  const std::lock_guard lock(mutex_);
  seconds_.at(index) = seconds;
}

std::vector<double> GemmLog::seconds() const {
  const std::lock_guard lock(mutex_);
  return seconds_;
}

std::vector<bool> GemmLog::with_row_passes() const {
  const std::lock_guard lock(mutex_);
  return row_passes_;
}

std::vector<GemmShape> GemmLog::shapes() const {
  const std::lock_guard lock(mutex_);
  return shapes_;
}

double GemmLog::flops() const {
  const std::lock_guard lock(mutex_);
  return std::accumulate(shapes_.begin(), shapes_.end(), 0.0,
                         [](double sum, const GemmShape& s) { return sum + s.flops(); });
}

namespace {

// Operands as large as the largest product of the list needs; every product reads and writes
// views of the same ones (their values do not matter, only that they are finite numbers).
struct Operands {
  RowMatrixXf a, b, c;
  std::vector<float> bias;

  explicit Operands(const std::vector<GemmShape>& shapes) {
    Eigen::Index a_size = 0, b_size = 0, c_size = 0, width = 0;
    for (const GemmShape& s : shapes) {
      a_size = std::max(a_size, s.m * s.k);
      b_size = std::max(b_size, s.k * s.n);
      c_size = std::max(c_size, s.m * s.n);
      width = std::max(width, s.n);
    }
    a = RowMatrixXf::Random(1, a_size);
    b = RowMatrixXf::Random(1, b_size);
    c = RowMatrixXf::Zero(1, c_size);
    bias.assign(static_cast<size_t>(width), 0.5f);
  }

  void run(const GemmShape& s) {
    using Map = Eigen::Map<RowMatrixXf>;
    const bool a_rows = s.op_a == Transpose::kNo, b_rows = s.op_b == Transpose::kNo;
    const Map a_view(a.data(), a_rows ? s.m : s.k, a_rows ? s.k : s.m);
    const Map b_view(b.data(), b_rows ? s.k : s.n, b_rows ? s.n : s.k);
    Map c_view(c.data(), s.m, s.n);
    if (s.bias) {
      gemm_bias(a_view, b_view, s.op_b, bias.data(), s.activation, c_view);
    } else {
      gemm(a_view, s.op_a, b_view, s.op_b, c_view, s.accumulate);
    }
  }
};

}  // namespace

double time_gemm_shapes(const std::vector<GemmShape>& shapes, double min_seconds, bool share_out,
                        std::vector<double>* each) {
  if (each != nullptr) each->assign(shapes.size(), 0.0);
  if (shapes.empty()) return 0.0;
  using Clock = std::chrono::steady_clock;
  const int threads = share_out ? Eigen::nbThreads() : 1;
  std::vector<Operands> operands;
  for (int t = 0; t < threads; ++t) operands.emplace_back(shapes);
  // Each product's seconds go to its own slot (no two threads share one).
  std::vector<double> sums(shapes.size(), 0.0);
  auto run = [&](int i, int thread) {
    const Clock::time_point start = Clock::now();
    operands[thread].run(shapes[i]);
    sums[i] += std::chrono::duration<double>(Clock::now() - start).count();
  };
  auto pass = [&] {
    if (!share_out) {
      for (int i = 0; i < static_cast<int>(shapes.size()); ++i) run(i, 0);
      return;
    }
    detail::parallel_for(static_cast<int>(shapes.size()), threads, detail::Schedule::kOneAtATime,
                         run);
  };
  pass();  // kernels compiled, pages touched
  std::fill(sums.begin(), sums.end(), 0.0);
  const Clock::time_point start = Clock::now();
  int passes = 0;
  double seconds = 0.0;
  do {
    pass();
    ++passes;
    seconds = std::chrono::duration<double>(Clock::now() - start).count();
  } while (seconds < min_seconds);
  if (each != nullptr) {
    for (size_t i = 0; i < sums.size(); ++i) (*each)[i] = sums[i] / passes;
  }
  return seconds / passes;
}

}  // namespace fignet
