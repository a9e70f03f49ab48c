#include <gtest/gtest.h>

#include <random>

#include "fignet/rollout/metrics.h"
#include "fignet/rollout/rigid_fit.h"
#include "fignet/rollout/rollout.h"
#include "trajectory_fixtures.h"

namespace fignet {
namespace {

TEST(RigidFit, RecoversAKnownRotationAndTranslation) {
  const auto mesh = testing::small_cube();
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
    const Vec3 t(n(rng), n(rng), n(rng));
    const Points moved =
        (mesh->vertices() * q.toRotationMatrix().transpose()).rowwise() + t.transpose();
    const Pose fit = fit_rigid_transform(mesh->vertices(), moved);
    EXPECT_LT(rotation_angle_degrees(fit.orientation, q), 1e-6);
    EXPECT_LT((fit.position - t).norm(), 1e-12);
  }
}

TEST(RigidFit, NeverReturnsAReflection) {
  const auto mesh = testing::small_cube();
  Points mirrored = mesh->vertices();
  mirrored.col(0) *= -1.0;  // the best orthogonal map would be a reflection
  const Pose fit = fit_rigid_transform(mesh->vertices(), mirrored);
  EXPECT_NEAR(fit.orientation.toRotationMatrix().determinant(), 1.0, 1e-12);
}

TEST(Rollout, ExactGravityReproducesBallisticMotion) {
  const double dt = 1.0 / 48.0;
  const Vec3 g(0, 0, -10);
  Trajectory truth;
  truth.time_step = dt;
  truth.objects.push_back(testing::ballistic_object(testing::small_cube(), Vec3(0, 0, 5),
                                                    Vec3(1, -2, 3), Vec3::Zero(), 40, dt, g));
  // A kinematic object moving along its own scripted path.
  TrajectoryObject pusher = testing::ballistic_object(
      testing::small_cube(), Vec3(3, 0, 0), Vec3(0.5, 0, 0), Vec3(0, 0, 1), 40, dt, Vec3::Zero());
  pusher.kinematic = true;
  truth.objects.push_back(pusher);
  GravityPredictor gravity(g, dt, 2);
  const Trajectory predicted = rollout(gravity, truth);
  for (int f = 0; f < 40; ++f) {
    EXPECT_LT((predicted.objects[0].poses[f].position - truth.objects[0].poses[f].position).norm(),
              1e-9)
        << "frame " << f;
    EXPECT_LT(rotation_angle_degrees(predicted.objects[0].poses[f].orientation,
                                     truth.objects[0].poses[f].orientation),
              1e-6);
    EXPECT_EQ(predicted.objects[1].poses[f].position, truth.objects[1].poses[f].position);
  }
  const RolloutErrors errors = rollout_errors(predicted, truth, 3);
  EXPECT_LT(errors.mean_translation, 1e-9);
}

TEST(Metrics, TranslationIsRmseAndRotationIsMeanAngle) {
  const auto mesh = testing::small_cube();
  Trajectory truth;
  for (int o = 0; o < 2; ++o) {
    truth.objects.push_back(testing::ballistic_object(mesh, Vec3(o, 0, 1), Vec3::Zero(),
                                                      Vec3::Zero(), 3, 0.1, Vec3::Zero()));
  }
  Trajectory predicted = truth;
  predicted.objects[0].poses[2].position += Vec3(0.3, 0.4, 0.0);  // 0.5 m off
  predicted.objects[1].poses[2].orientation = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ());
  const RolloutErrors errors = rollout_errors(predicted, truth, 1);
  EXPECT_NEAR(errors.translation[2], std::sqrt(0.25 / 2), 1e-12);
  EXPECT_NEAR(errors.rotation[2], 45.0, 1e-9);
  EXPECT_NEAR(errors.final_translation, std::sqrt(0.125), 1e-12);
  EXPECT_NEAR(errors.mean_translation, std::sqrt(0.125) / 2, 1e-12);  // frames 1 and 2
  EXPECT_NEAR(rotation_angle_degrees(Eigen::Quaterniond::Identity(),
                                     Eigen::Quaterniond(Eigen::AngleAxisd(3.0, Vec3::UnitX()))),
              3.0 * 180 / M_PI, 1e-9);
}

// Travel: each predicted frame's step of every dynamic centre from the frame before, summed, in
// the rollout and in the truth; kinematic objects and the given frames left out.
TEST(Metrics, TravelSumsTheCentresStepsOverThePredictedFrames) {
  const auto mesh = testing::small_cube();
  Trajectory truth;
  truth.objects.push_back(testing::ballistic_object(mesh, Vec3::Zero(), Vec3(1, 0, 0), Vec3::Zero(),
                                                    4, 1.0, Vec3::Zero()));
  TrajectoryObject pusher = testing::ballistic_object(mesh, Vec3(0, 5, 0), Vec3(0, 3, 0),
                                                      Vec3::Zero(), 4, 1.0, Vec3::Zero());
  pusher.kinematic = true;
  truth.objects.push_back(pusher);
  Trajectory predicted = truth;
  predicted.objects[0].poses[2].position = Vec3(1.5, 0, 0);  // 0.5 m from frame 1
  predicted.objects[0].poses[3].position = Vec3(1.5, 0, 2);  // then 2 m up
  predicted.objects[1].poses[3].position = Vec3(0, 100, 0);  // kinematic: not counted
  const RolloutErrors errors = rollout_errors(predicted, truth, 2);
  EXPECT_NEAR(errors.true_travel, 2.0, 1e-12);  // frames 1 → 2 → 3, 1 m each
  EXPECT_NEAR(errors.predicted_travel, 2.5, 1e-12);
  // From the first frame on, the first frame has no step to count.
  EXPECT_NEAR(rollout_errors(truth, truth, 0).true_travel, 3.0, 1e-12);
}

TEST(Metrics, PenetrationCountsCrossingFacesAndDepth) {
  const auto mesh = testing::small_cube(0.5);
  Trajectory scene;
  scene.floor = Floor{};
  for (int o = 0; o < 2; ++o) {
    scene.objects.push_back(testing::ballistic_object(mesh, Vec3(0.9 * o, 0, 0.5), Vec3::Zero(),
                                                      Vec3::Zero(), 1, 0.1, Vec3::Zero()));
  }
  // Overlap of 0.1 m along x: the four x-face corners of each cube are 0.1 m deep in the other.
  const Penetration overlapping = measure_penetration(scene, 0);
  EXPECT_GT(overlapping.intersecting_face_pairs, 0);
  EXPECT_NEAR(overlapping.depth, 0.0, 0.81);  // bounded: at most 8 vertices x 0.1 m
  EXPECT_GT(overlapping.depth, 0.0);
  scene.objects[1].poses[0].position.x() = 1.5;
  const Penetration apart = measure_penetration(scene, 0);
  EXPECT_EQ(apart.intersecting_face_pairs, 0);
  EXPECT_EQ(apart.depth, 0.0);
  scene.objects[1].poses[0].position.z() = 0.3;  // 0.2 m below the floor: 4 bottom vertices
  EXPECT_NEAR(measure_penetration(scene, 0).depth, 4 * 0.2, 1e-12);
  // A rollout sinking twice as deep as the truth has a depth ratio of 2.
  Trajectory deeper = scene;
  deeper.objects[1].poses[0].position.z() = 0.1;
  EXPECT_NEAR(penetration_ratio(deeper, scene, 0).depth, 2.0, 1e-12);
  EXPECT_TRUE(std::isnan(penetration_ratio(deeper, scene, 0).count));  // no crossings in truth
}

}  // namespace
}  // namespace fignet
