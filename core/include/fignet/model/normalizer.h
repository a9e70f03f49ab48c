// Online per-column mean and standard deviation (MeshGraphNets style): statistics accumulate
// during the first training steps and are frozen after a configured number of accumulations.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "fignet/nn/buffer.h"

namespace fignet {

class Normalizer {
 public:
  static constexpr double kStdEpsilon = 1e-8;

  Normalizer() = default;
  Normalizer(int size, std::int64_t max_accumulations);

  // Adds the rows' statistics, counting one accumulation; does nothing once frozen.
  void accumulate(const ConstMatrixRef& rows);
  // The same with the statistics already summed (over the processes of data-parallel training):
  // `count` rows whose columns sum to `sum` and their squares to `sum_squares`.
  void add(double count, const Eigen::VectorXd& sum, const Eigen::VectorXd& sum_squares);
  bool frozen() const { return accumulations_ >= max_accumulations_; }

  // out = (in − mean)/std. Columns that never varied are only centred (std taken as 1), so a
  // value unseen in training cannot be blown up by a 1e-8 divisor.
  void normalize(const ConstMatrixRef& in, MatrixRef out) const;
  // out = in·std + mean.
  void denormalize(const ConstMatrixRef& in, MatrixRef out) const;
  const Eigen::RowVectorXf& mean() const { return mean_; }
  const Eigen::RowVectorXf& std() const { return std_; }
  int size() const { return static_cast<int>(sum_.size()); }

  // Raw state, for model files and for merging statistics across processes.
  std::int64_t accumulations() const { return accumulations_; }
  std::int64_t max_accumulations() const { return max_accumulations_; }
  double count() const { return count_; }
  const Eigen::VectorXd& sum() const { return sum_; }
  const Eigen::VectorXd& sum_squares() const { return sum_squares_; }
  void set_state(std::int64_t accumulations, double count, Eigen::VectorXd sum,
                 Eigen::VectorXd sum_squares);

 private:
  std::int64_t accumulations_ = 0, max_accumulations_ = 1;
  // Recomputes the cached mean and std from the sums (after every change of them), so that
  // normalising a step allocates nothing.
  void update_cache();

  double count_ = 0.0;
  Eigen::VectorXd sum_, sum_squares_;
  Eigen::RowVectorXf mean_, std_, inverse_std_;
  Eigen::VectorXd scratch_sum_, scratch_squares_;  // accumulate()'s, kept to avoid allocating
};

}  // namespace fignet
