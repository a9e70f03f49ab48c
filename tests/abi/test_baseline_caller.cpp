// This file is compiled for baseline x86-64 (SSE2) while fignet_core is compiled for x86-64-v3,
// as a user's program built with its own flags would be. Eigen sizes its alignment, and with it
// the allocator behind the core's buffers and the layout of its quaternions, from the
// instruction set; fignet_core fixes both for every user (EIGEN_MAX_ALIGN_BYTES,
// EIGEN_MAX_STATIC_ALIGN_BYTES), so objects built here may be grown and freed by the core.
// Without that, the CUDA backend (built without the project's flags) crashed in the core's
// forward_backward freeing a buffer its own constructor had allocated.
#include <gtest/gtest.h>

#include "fignet/model/network_backend.h"
#include "fignet/rollout/rigid_fit.h"

namespace fignet {
namespace {

// A backend whose forward returns `rows` zero rows, whatever the graph.
class ZeroBackend final : public NetworkBackend {
 public:
  explicit ZeroBackend(int rows) : output_(RowMatrixXf::Zero(rows, 3)) {}
  std::string name() const override { return "zero"; }
  ConstMatrixView forward(const float*, const Normalizers&, const Graph&, bool) override {
    return {output_.data(), output_.rows(), 3};
  }
  void backward(const float*, float* grads, const Graph&, const ConstMatrixRef& d) override {
    grads[0] += d.sum();
  }

 private:
  RowMatrixXf output_;
};

TEST(BaselineCaller, TheCoreGrowsAndFreesABufferConstructedHere) {
  // NetworkBackend's buffer is allocated by its constructor, inline here; forward_backward, in
  // the core, grows it to 1000 x 3 and so frees the first allocation.
  ZeroBackend backend(1000);
  const Normalizers normalizers;
  const Graph graph;
  float grad = 0.0f;
  const double loss = backend.forward_backward(nullptr, normalizers, graph, &grad,
                                               [](int, const ConstMatrixRef& out, MatrixRef d) {
                                                 d.setConstant(1.0f);
                                                 return double(out.rows());
                                               });
  EXPECT_EQ(loss, 1000.0);
  EXPECT_EQ(grad, 3000.0f);
}

TEST(BaselineCaller, PosesHaveTheCoresLayout) {
  // Quaterniond (32 bytes) is aligned to 32 under AVX and to 16 without it, unless fixed.
  EXPECT_EQ(alignof(Eigen::Quaterniond), 32u);
  EXPECT_EQ(alignof(Pose), 32u);
  // Vertices made here, a pose made by the core: the rigid fit of a known motion.
  Points rest(4, 3), moved(4, 3);
  rest << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  const Vec3 position(0.5, -0.2, 0.3);
  const Eigen::Quaterniond orientation(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  for (int i = 0; i < 4; ++i)
    moved.row(i) = (orientation * Vec3(rest.row(i)) + position).transpose();
  const Pose fitted = fit_rigid_transform(rest, moved);
  EXPECT_LT((fitted.position - position).norm(), 1e-9);
  EXPECT_LT(fitted.orientation.angularDistance(orientation), 1e-9);
}

}  // namespace
}  // namespace fignet
