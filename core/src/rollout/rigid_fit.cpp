#include "fignet/rollout/rigid_fit.h"

#include <Eigen/SVD>

namespace fignet {

Pose fit_rigid_transform(const Eigen::Ref<const Points>& rest,
                         const Eigen::Ref<const Points>& moved) {
  const Eigen::RowVector3d rest_mean = rest.colwise().mean();
  const Eigen::RowVector3d moved_mean = moved.colwise().mean();
  // Cross-covariance of the centred point sets; R = V·diag(1, 1, d)·Uᵀ with d fixing reflections.
  const Eigen::Matrix3d covariance =
      (rest.rowwise() - rest_mean).transpose() * (moved.rowwise() - moved_mean);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d correction = Eigen::Matrix3d::Identity();
  correction(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  const Eigen::Matrix3d rotation = svd.matrixV() * correction * svd.matrixU().transpose();
  Pose pose;
  pose.orientation = Eigen::Quaterniond(rotation).normalized();
  pose.position = moved_mean.transpose() - rotation * rest_mean.transpose();
  return pose;
}

}  // namespace fignet
