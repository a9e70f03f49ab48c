// evaluate_rollouts against a hand-computed case: a predictor that applies gravity to a body that
// in truth flies without it errs by g·dt²·k(k+1)/2 after k predicted steps.
#include <gtest/gtest.h>

#include "fignet/error.h"
#include "fignet/rollout/evaluation.h"
#include "trajectory_fixtures.h"

namespace fignet {
namespace {

TEST(Evaluation, ErrorsMatchAHandComputedCase) {
  const double dt = 0.1;
  const int frames = 8;
  const Vec3 g(0, 0, -10);
  Trajectory truth;
  truth.time_step = dt;
  truth.gravity = Vec3::Zero();
  truth.objects.push_back(testing::ballistic_object(
      testing::small_cube(), Vec3(0, 0, 5), Vec3(1, 0, 0), Vec3::Zero(), frames, dt, Vec3::Zero()));
  const std::vector<Trajectory> set = {truth, truth};
  GravityPredictor predictor(g, dt, 2);
  const Evaluation e = evaluate_rollouts(predictor, set);

  // Frames 0–2 are given; frame 2 + k is k steps into the rollout.
  ASSERT_EQ(static_cast<int>(e.translation.size()), frames);
  double sum = 0.0;
  for (int f = 0; f < frames; ++f) {
    const int k = std::max(0, f - 2);
    const double expected = 10.0 * dt * dt * k * (k + 1) / 2.0;
    EXPECT_NEAR(e.translation[f], expected, 1e-9) << "frame " << f;
    EXPECT_NEAR(e.rotation[f], 0.0, 1e-9);
    if (f >= 3) sum += expected;
  }
  EXPECT_NEAR(e.mean_translation, sum / (frames - 3), 1e-9);
  EXPECT_NEAR(e.final_translation, 10.0 * dt * dt * 5 * 6 / 2.0, 1e-9);
  EXPECT_EQ(e.trajectories, 2);
  EXPECT_EQ(e.face_edges_per_step, 0.0);
  EXPECT_TRUE(std::isnan(e.penetration_depth_ratio));  // not measured
}

}  // namespace
}  // namespace fignet

namespace fignet {
namespace {

// A set evaluated in two shares (as two processes would), sent through the flat form and merged,
// summarises to the same figures as the whole set at once.
TEST(Evaluation, SharesMergeToTheWhole) {
  const double dt = 0.1;
  std::vector<Trajectory> set;
  for (int i = 0; i < 3; ++i) {
    Trajectory t;
    t.time_step = dt;
    t.gravity = Vec3::Zero();
    t.objects.push_back(testing::ballistic_object(testing::small_cube(), Vec3(0, 0, 5),
                                                  Vec3(i, 0, 0), Vec3(0, 0, 0.5 * i), 6 + i, dt,
                                                  Vec3::Zero()));
    set.push_back(t);
  }
  GravityPredictor predictor(Vec3(0, 0, -10), dt, 2);
  const Evaluation whole = evaluate_rollouts(predictor, set);
  EvaluationTotals merged = EvaluationTotals::deserialize(
      evaluate_rollout_totals(predictor, std::span(set).first(1)).serialize());
  merged += EvaluationTotals::deserialize(
      evaluate_rollout_totals(predictor, std::span(set).subspan(1)).serialize());
  const Evaluation parts = summarize(merged);
  EXPECT_EQ(parts.trajectories, 3);
  EXPECT_EQ(parts.translation, whole.translation);
  EXPECT_EQ(parts.rotation, whole.rotation);
  EXPECT_DOUBLE_EQ(parts.mean_translation, whole.mean_translation);
  EXPECT_DOUBLE_EQ(parts.final_rotation, whole.final_rotation);
  EXPECT_DOUBLE_EQ(parts.travel_ratio, whole.travel_ratio);
  // The predictor's gravity is not the data's (none): its bodies travel farther.
  EXPECT_GT(whole.travel_ratio, 1.0);
  EXPECT_THROW(EvaluationTotals::deserialize(std::vector<double>{2.0, 1.0}), ConfigError);
}

}  // namespace
}  // namespace fignet
