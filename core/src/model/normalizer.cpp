#include "fignet/model/normalizer.h"

#include <algorithm>
#include <cmath>

namespace fignet {

Normalizer::Normalizer(int size, std::int64_t max_accumulations)
    : max_accumulations_(max_accumulations),
      sum_(Eigen::VectorXd::Zero(size)),
      sum_squares_(Eigen::VectorXd::Zero(size)) {
  update_cache();
}

void Normalizer::accumulate(const ConstMatrixRef& rows) {
  if (frozen() || rows.rows() == 0) return;
  // One pass in double, row by row (no copy of the rows: batches have ~10^5 of them).
  const int n = size();
  scratch_sum_.setZero(n);
  scratch_squares_.setZero(n);
  for (Eigen::Index r = 0; r < rows.rows(); ++r) {
    const float* row = rows.row(r).data();
    for (int c = 0; c < n; ++c) {
      const double value = row[c];
      scratch_sum_[c] += value;
      scratch_squares_[c] += value * value;
    }
  }
  add(static_cast<double>(rows.rows()), scratch_sum_, scratch_squares_);
}

void Normalizer::add(double count, const Eigen::VectorXd& sum, const Eigen::VectorXd& sum_squares) {
  if (frozen() || count == 0.0) return;
  sum_ += sum;
  sum_squares_ += sum_squares;
  count_ += count;
  ++accumulations_;
  update_cache();
}

void Normalizer::update_cache() {
  const int n = size();
  mean_ = Eigen::RowVectorXf::Zero(n);
  std_ = Eigen::RowVectorXf::Ones(n);
  if (count_ > 0.0) {
    for (int c = 0; c < n; ++c) {
      const double mean = sum_[c] / count_;
      const double variance = std::max(sum_squares_[c] / count_ - mean * mean, 0.0);
      mean_[c] = static_cast<float>(mean);
      if (std::sqrt(variance) > kStdEpsilon) std_[c] = static_cast<float>(std::sqrt(variance));
    }
  }
  inverse_std_ = std_.cwiseInverse();
}

void Normalizer::normalize(const ConstMatrixRef& in, MatrixRef out) const {
  out = ((in.rowwise() - mean_).array().rowwise() * inverse_std_.array()).matrix();
}

void Normalizer::denormalize(const ConstMatrixRef& in, MatrixRef out) const {
  out = (in.array().rowwise() * std_.array()).matrix();
  out.rowwise() += mean_;
}

void Normalizer::set_state(std::int64_t accumulations, double count, Eigen::VectorXd sum,
                           Eigen::VectorXd sum_squares) {
  accumulations_ = accumulations;
  count_ = count;
  sum_ = std::move(sum);
  sum_squares_ = std::move(sum_squares);
  update_cache();
}

}  // namespace fignet
