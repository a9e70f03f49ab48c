#include "fignet/model/normalizer.h"

#include <cmath>

namespace fignet {

Normalizer::Normalizer(int size, std::int64_t max_accumulations)
    : max_accumulations_(max_accumulations),
      sum_(Eigen::VectorXd::Zero(size)),
      sum_squares_(Eigen::VectorXd::Zero(size)) {}

void Normalizer::accumulate(const ConstMatrixRef& rows) {
  if (frozen() || rows.rows() == 0) return;
  const Eigen::MatrixXd values = rows.cast<double>();
  sum_ += values.colwise().sum().transpose();
  sum_squares_ += values.array().square().colwise().sum().matrix().transpose();
  count_ += static_cast<double>(rows.rows());
  ++accumulations_;
}

Eigen::RowVectorXf Normalizer::mean() const {
  if (count_ == 0.0) return Eigen::RowVectorXf::Zero(size());
  return (sum_ / count_).transpose().cast<float>();
}

Eigen::RowVectorXf Normalizer::std() const {
  Eigen::RowVectorXf result = Eigen::RowVectorXf::Ones(size());
  if (count_ == 0.0) return result;
  for (int c = 0; c < size(); ++c) {
    const double mean = sum_[c] / count_;
    const double variance = std::max(sum_squares_[c] / count_ - mean * mean, 0.0);
    const double std = std::sqrt(variance);
    if (std > kStdEpsilon) result[c] = static_cast<float>(std);
  }
  return result;
}

void Normalizer::normalize(const ConstMatrixRef& in, MatrixRef out) const {
  const Eigen::RowVectorXf m = mean(), inv = std().cwiseInverse();
  out = ((in.rowwise() - m).array().rowwise() * inv.array()).matrix();
}

void Normalizer::denormalize(const ConstMatrixRef& in, MatrixRef out) const {
  const Eigen::RowVectorXf m = mean(), s = std();
  out = (in.array().rowwise() * s.array()).matrix();
  out.rowwise() += m;
}

void Normalizer::set_state(std::int64_t accumulations, double count, Eigen::VectorXd sum,
                           Eigen::VectorXd sum_squares) {
  accumulations_ = accumulations;
  count_ = count;
  sum_ = std::move(sum);
  sum_squares_ = std::move(sum_squares);
}

}  // namespace fignet
